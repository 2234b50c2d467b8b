// index_vertices at one thread numbers the distinct (vertex of A, vertex of B) pairs of the
// corners by bit sets of partners per vertex of A when those rows are few for the corners,
// else by lists at the vertices of the operand with more vertices. Either way the pairs must
// come out sorted, each once, and each corner must name its own pair.
#include <doctest/doctest.h>

#include <cstdint>
#include <set>
#include <vector>

#include "fims.h"
#include "parallel.h"

namespace {

struct Corners {
  morph::detail::SumFacets facets;
  std::set<std::uint64_t> expected;
  void add(int i, int j) {
    const std::uint64_t key = morph::detail::pair_key(i, j);
    facets.corners.push_back(key);
    expected.insert(key);
  }
  void end_facet() { facets.face_begin.push_back(static_cast<int>(facets.corners.size())); }
};

void check_numbering(const Corners& c, int num_a, int num_b) {
  std::vector<std::uint64_t> pairs;
  std::vector<int> corners;
  morph::detail::run_with_threads(
      1, [&] { morph::detail::index_vertices(c.facets, num_a, num_b, pairs, corners); });
  CHECK(pairs == std::vector<std::uint64_t>(c.expected.begin(), c.expected.end()));
  REQUIRE(corners.size() == c.facets.corners.size());
  int wrong = 0;
  for (std::size_t k = 0; k < corners.size(); ++k)
    wrong += corners[k] < 0 || corners[k] >= static_cast<int>(pairs.size()) ||
             pairs[corners[k]] != c.facets.corners[k];
  CHECK(wrong == 0);
}

}  // namespace

// Few rows (the bit sets): B with up to a word of vertices and with a few words, the pairs at
// the words' first and last bits (j = 0, 63, 64, 127, ...) among random ones, repeated.
TEST_CASE("index_vertices numbers the pairs by bit sets of partners") {
  for (const int num_b : {1, 5, 63, 64, 65, 128, 130}) {
    const int num_a = 200;
    Corners c;
    unsigned state = 777u + static_cast<unsigned>(num_b);
    const auto next = [&](int n) {
      state = state * 1103515245u + 12345u;
      return static_cast<int>((state >> 8) % static_cast<unsigned>(n));
    };
    for (int f = 0; f < 3000; ++f) {
      for (int k = 0; k < 4; ++k) {
        const int i = next(num_a);
        // Every fourth corner at a word's edge, the others anywhere.
        const int edge = (next(2) == 0 ? 0 : 63) + 64 * next((num_b + 63) / 64);
        c.add(i, k == 0 && edge < num_b ? edge : next(num_b));
      }
      c.end_facet();
    }
    CHECK(c.expected.size() > 100);
    check_numbering(c, num_a, num_b);
    // The same pairs with A and B swapped: rows of 200 partners (four words each).
    Corners swapped;
    for (const std::uint64_t key : c.facets.corners)
      swapped.add(morph::detail::pair_second(key), morph::detail::pair_first(key));
    swapped.facets.face_begin = c.facets.face_begin;
    check_numbering(swapped, num_b, num_a);
  }
}

// Many rows for the corners (two large operands, a few partners per vertex): the lists, listed
// by either operand, each vertex's partners found out of order.
TEST_CASE("index_vertices numbers the pairs of large operands in lists") {
  for (const bool more_b : {false, true}) {
    const int num_a = more_b ? 2500 : 3000, num_b = more_b ? 3000 : 2500;
    Corners c;
    for (int round = 0; round < 3; ++round)
      for (int v = 0; v < 2500; ++v) {
        const int u = (v * 7919 + round * 31) % 2500;
        c.add(u, (u * 13) % 2500);
        c.add((u + 1) % 2500, (u * 13 + 1) % 2500);
        c.add(u, (u * 13 + 2) % 2500);
        c.end_facet();
      }
    check_numbering(c, num_a, num_b);
  }
}
