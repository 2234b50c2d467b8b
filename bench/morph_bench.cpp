// morph-bench: how fast libmorph's FIMS kernel and morphology are, and how they scale.
//
//   morph-bench                  Table 1, morphology rows, quick scaling (a few minutes at most)
//   morph-bench --table1         Table 1 of the FIMS paper: libmorph against the hull route
//   morph-bench --morphology     erosion, opening and closing on the Table 1 operands
//   morph-bench --scaling        full scaling to >= 300,000 input facets of the sum (log-log
//                                slope, peak memory) and of dilation, erosion, opening, closing
//   morph-bench --all            all of the above with the full scaling
//   --csv DIR                    also write table1.csv, morphology.csv, scaling.csv and
//                                morphology_scaling.csv into DIR
//   --markdown FILE              also write the report (Markdown tables) to FILE
//   --samples DIR                where the sample meshes are (default: the source tree's samples/)
//   --budget SECONDS             time aimed at per measurement, repetitions included (default 1)
//   --filter TEXT                Table 1 and morphology: only the pairs whose "A + B" contains TEXT
//   --loop A B SECONDS [THREADS] only A (+) B with libmorph, repeated for SECONDS (for perf
//   record);
//                                A and B are sample files, B = "rotated" is A turned as in Table 1
//   --op erode|open|close        before --loop: loop this operation instead (B scaled as in the
//                                morphology rows)
//   --malloc-defaults            keep glibc's allocator defaults (by default the bench, like the
//                                apps, keeps freed memory for reuse: common/allocator.h)
//
// Every measurement runs once as a warm-up (not counted), then repeats as many times as
// fit in the budget (3 to 1000 times; 5 at most in the scaling series) and reports the median. The
// hull route is what a user without a Minkowski-sum kernel writes: all vertex sums a_i + b_j,
// CGAL's convex_hull_3 with the Epick kernel into a Surface_mesh. See docs/benchmarks.md.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>
#include <morph/io.h>
#include <morph/minkowski_sum.h>
#include <morph/morphology.h>
#include <morph/structuring_element.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "common/allocator.h"

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using HullMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using morph::Mesh;

// Rotation of the second operand in the "rotated icosphere" cases: small enough that the
// sum stays close to the aligned one, large enough that no facet of A is parallel to one
// of B (the aligned sum of two equal icospheres is degenerate: every facet coincides).
constexpr double kRotationAngle = 0.01;               // radians, about kRotationAxis
constexpr double kRotationAxis[3] = {1.0, 2.0, 3.0};  // generic; normalised before use

// The morphology rows scale B by this factor: the samples all have radius about 1, and
// a unit sphere fits inside none of them, so unscaled erosions would all be empty.
constexpr double kMorphologyScale = 0.25;

// Seeds of the random polytopes of the scaling series (hulls of points on the unit sphere).
constexpr unsigned kSeedA = 20240501;
constexpr unsigned kSeedB = 20240502;

struct Settings {
  bool table1 = false;
  bool morphology = false;
  bool scaling = false;
  bool full_scaling = false;
  std::filesystem::path samples = MORPH_SAMPLES_DIR;
  std::filesystem::path csv_dir;   // empty: no CSV
  std::filesystem::path markdown;  // empty: no file
  std::string filter;              // Table 1 / morphology pairs whose "A + B" contains it
  std::string loop_op = "sum";     // what --loop repeats: sum, erode, open, close
  double budget_seconds = 1.0;
  int min_reps = 3;
  // Enough samples to fill the budget for sub-millisecond operations: 15 samples of a 0.4 ms
  // sum are 6 ms of measurement, and one burst of host noise then moved the median by 10-20%.
  int max_reps = 1000;
};

// ---------------------------------------------------------------------------------------
// Timing

using Clock = std::chrono::steady_clock;

double milliseconds_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

struct Timing {
  double median_ms = 0.0;
  int reps = 0;
};

// Warm-up run (not counted), then as many runs as fit in the budget, within the rep limits.
Timing time_median(const std::function<void()>& run, const Settings& settings) {
  const auto warm_start = Clock::now();
  run();
  const double warm_ms = milliseconds_since(warm_start);
  const double budget_ms = settings.budget_seconds * 1000.0;
  const int reps = std::clamp(static_cast<int>(budget_ms / std::max(warm_ms, 1e-3)),
                              settings.min_reps, settings.max_reps);
  std::vector<double> samples;
  for (int i = 0; i < reps; ++i) {
    const auto start = Clock::now();
    run();
    samples.push_back(milliseconds_since(start));
  }
  return {median(samples), reps};
}

long peak_rss_kib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;  // KiB on Linux
}

// ---------------------------------------------------------------------------------------
// Operands

Mesh rotated(const Mesh& mesh, double angle) {
  const double norm =
      std::sqrt(kRotationAxis[0] * kRotationAxis[0] + kRotationAxis[1] * kRotationAxis[1] +
                kRotationAxis[2] * kRotationAxis[2]);
  const double x = kRotationAxis[0] / norm, y = kRotationAxis[1] / norm,
               z = kRotationAxis[2] / norm;
  const double c = std::cos(angle), s = std::sin(angle), t = 1.0 - c;
  const double r[3][3] = {{t * x * x + c, t * x * y - s * z, t * x * z + s * y},
                          {t * x * y + s * z, t * y * y + c, t * y * z - s * x},
                          {t * x * z - s * y, t * y * z + s * x, t * z * z + c}};
  Mesh out = mesh;
  for (auto v : out.vertices()) {
    const auto p = mesh.point(v);
    out.set_point(v, {r[0][0] * p[0] + r[0][1] * p[1] + r[0][2] * p[2],
                      r[1][0] * p[0] + r[1][1] * p[1] + r[1][2] * p[2],
                      r[2][0] * p[0] + r[2][1] * p[1] + r[2][2] * p[2]});
  }
  return out;
}

Mesh scaled(const Mesh& mesh, double factor) {
  Mesh out = mesh;
  for (auto v : out.vertices()) out.set_point(v, mesh.point(v) * factor);
  return out;
}

Mesh to_mesh(const HullMesh& hull) {
  Mesh mesh;
  std::vector<Mesh::VertexHandle> handle(hull.number_of_vertices());
  for (auto v : hull.vertices()) {
    const auto& p = hull.point(v);
    handle[v.idx()] = mesh.add_vertex({p.x(), p.y(), p.z()});
  }
  std::vector<Mesh::VertexHandle> face;
  for (auto f : hull.faces()) {
    face.clear();
    for (auto v : CGAL::vertices_around_face(hull.halfedge(f), hull))
      face.push_back(handle[v.idx()]);
    mesh.add_face(face);
  }
  return mesh;
}

// Convex hull of n random points on the unit sphere (all of them are vertices): a
// triangulated polytope with 2n - 4 facets and no symmetry.
Mesh random_polytope(int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<Kernel::Point_3> points;
  points.reserve(n);
  while (static_cast<int>(points.size()) < n) {
    const double x = normal(rng), y = normal(rng), z = normal(rng);
    const double r = std::sqrt(x * x + y * y + z * z);
    if (r > 1e-6) points.emplace_back(x / r, y / r, z / r);
  }
  HullMesh hull;
  CGAL::convex_hull_3(points.begin(), points.end(), hull);
  return to_mesh(hull);
}

struct Operand {
  std::string name;
  Mesh mesh;
};

Operand sample(const Settings& settings, const std::string& file) {
  return {file, morph::read_mesh(settings.samples / file)};
}

// ---------------------------------------------------------------------------------------
// The two routes

struct Counts {
  std::size_t vertices = 0;
  std::size_t facets = 0;
};

Counts libmorph_sum(const Mesh& A, const Mesh& B, int threads) {
  const auto sum = morph::minkowski_sum(A, B, {.threads = threads});
  return {sum.mesh.n_vertices(), sum.mesh.n_faces()};
}

// The hull route: every vertex sum, then CGAL's convex hull (triangles).
Counts hull_route(const Mesh& A, const Mesh& B) {
  std::vector<Kernel::Point_3> sums;
  sums.reserve(A.n_vertices() * B.n_vertices());
  for (auto va : A.vertices()) {
    const auto a = A.point(va);
    for (auto vb : B.vertices()) {
      const auto b = B.point(vb);
      sums.emplace_back(a[0] + b[0], a[1] + b[1], a[2] + b[2]);
    }
  }
  HullMesh hull;
  CGAL::convex_hull_3(sums.begin(), sums.end(), hull);
  return {hull.number_of_vertices(), hull.number_of_faces()};
}

// ---------------------------------------------------------------------------------------
// Output: the same rows as Markdown (stdout and --markdown) and CSV (--csv)

struct Table {
  std::string title;
  std::string csv_name;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> notes;  // printed under the table
};

std::string fixed(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, value);
  return buffer;
}

// Milliseconds with three significant digits or more.
std::string ms(double value) {
  return fixed(value, value >= 100 ? 0 : value >= 10 ? 1 : value >= 1 ? 2 : 3);
}

std::string ratio(double r) { return fixed(r, r < 10 ? 1 : 0) + "x"; }

std::string markdown(const Table& table) {
  std::ostringstream out;
  out << "### " << table.title << "\n\n|";
  for (const auto& h : table.header) out << ' ' << h << " |";
  out << "\n|";
  for (std::size_t i = 0; i < table.header.size(); ++i) out << (i < 2 ? "---|" : "---:|");
  out << '\n';
  for (const auto& row : table.rows) {
    out << '|';
    for (const auto& cell : row) out << ' ' << cell << " |";
    out << '\n';
  }
  if (!table.notes.empty()) out << '\n';
  for (const auto& note : table.notes) out << note << '\n';
  out << '\n';
  return out.str();
}

void write_csv(const Table& table, const std::filesystem::path& dir) {
  std::ofstream out(dir / table.csv_name);
  auto line = [&](const std::vector<std::string>& cells) {
    for (std::size_t i = 0; i < cells.size(); ++i) {
      std::string cell = cells[i];
      std::erase(cell, '`');
      out << (i ? "," : "") << '"' << cell << '"';
    }
    out << '\n';
  };
  line(table.header);
  for (const auto& row : table.rows) line(row);
  if (!out) throw std::runtime_error("cannot write " + (dir / table.csv_name).string());
}

class Report {
 public:
  explicit Report(const Settings& settings) : settings_(settings) {}
  void text(const std::string& s) {
    std::cout << s << std::flush;
    markdown_ += s;
  }
  void table(const Table& table) {
    text(markdown(table));
    if (!settings_.csv_dir.empty()) write_csv(table, settings_.csv_dir);
  }
  void finish() const {
    if (settings_.markdown.empty()) return;
    std::ofstream out(settings_.markdown);
    out << markdown_;
    if (!out) throw std::runtime_error("cannot write " + settings_.markdown.string());
  }

 private:
  const Settings& settings_;
  std::string markdown_;
};

// ---------------------------------------------------------------------------------------
// Table 1

struct Pair {
  Operand a;
  Operand b;
};

std::vector<Pair> table1_pairs(const Settings& settings) {
  auto s = [&](const char* file) { return sample(settings, file); };
  Operand ico5120 = s("icosphere_5120.off");
  Operand ico5120_rotated{"icosphere_5120.off rotated", rotated(ico5120.mesh, kRotationAngle)};
  std::vector<Pair> pairs{{s("hedra.off"), s("icosphere_320.off")},
                          {s("hedra.off"), s("icosphere_1280.off")},
                          {s("cube.off"), s("icosphere_320.off")},
                          {s("cube.off"), s("icosphere_1280.off")},
                          {s("icosphere_80.off"), s("icosphere_320.off")},
                          {s("icosphere_320.off"), s("icosphere_1280.off")},
                          {s("uvsphere_1600.off"), s("snub_dodecahedron.off")},
                          {ico5120, ico5120_rotated}};
  std::erase_if(pairs, [&](const Pair& p) {
    return (p.a.name + " + " + p.b.name).find(settings.filter) == std::string::npos;
  });
  return pairs;
}

std::string operand_cell(const Operand& op) {
  return "`" + op.name + "` (" + std::to_string(op.mesh.n_faces()) + ")";
}

void run_table1(const std::vector<Pair>& pairs, const Settings& settings, Report& report) {
  Table table{"Table 1: A (+) B, libmorph against the hull route",
              "table1.csv",
              {"A (facets)", "B (facets)", "libmorph 1 thread (ms)", "libmorph all threads (ms)",
               "hull route (ms)", "hull / libmorph (1 thread)", "hull / libmorph (all threads)",
               "libmorph V / F", "hull V / triangles", "reps lib / hull"},
              {},
              {}};
  for (const auto& [a, b] : pairs) {
    std::cerr << "  table 1: " << a.name << " + " << b.name << '\n';
    Counts lib, hull;
    const Timing one = time_median([&] { lib = libmorph_sum(a.mesh, b.mesh, 1); }, settings);
    const Timing all = time_median([&] { lib = libmorph_sum(a.mesh, b.mesh, 0); }, settings);
    const Timing ref = time_median([&] { hull = hull_route(a.mesh, b.mesh); }, settings);
    table.rows.push_back({operand_cell(a), operand_cell(b), ms(one.median_ms), ms(all.median_ms),
                          ms(ref.median_ms), ratio(ref.median_ms / one.median_ms),
                          ratio(ref.median_ms / all.median_ms),
                          std::to_string(lib.vertices) + " / " + std::to_string(lib.facets),
                          std::to_string(hull.vertices) + " / " + std::to_string(hull.facets),
                          std::to_string(one.reps) + " / " + std::to_string(ref.reps)});
  }
  table.notes.push_back(
      "Median times in milliseconds, warm-up excluded. libmorph: `morph::minkowski_sum` "
      "(operand validation included), facets kept as polygons. Hull route: all |A||B| vertex "
      "sums, `CGAL::convex_hull_3` (Epick) into a `Surface_mesh` (triangles). The rotated "
      "icosphere is turned by " +
      fixed(kRotationAngle, 2) + " rad about (1, 2, 3).");
  report.table(table);
}

// ---------------------------------------------------------------------------------------
// Morphology rows

std::string result_cell(const morph::MorphResult& r) {
  if (r.empty_reason == morph::EmptyReason::empty) return "empty";
  if (r.empty_reason == morph::EmptyReason::flat) return "flat";
  return std::to_string(r.mesh.n_faces());
}

void run_morphology(const std::vector<Pair>& pairs, const Settings& settings, Report& report) {
  using Op = morph::MorphResult (*)(const Mesh&, const Mesh&, const morph::MorphologyOptions&);
  const std::pair<const char*, Op> ops[] = {{"dilate", &morph::dilate},
                                            {"erode", &morph::erode},
                                            {"open", &morph::open},
                                            {"close", &morph::close}};
  Table table{"Morphology: dilation, erosion, opening, closing by B scaled by " +
                  fixed(kMorphologyScale, 2),
              "morphology.csv",
              {"A (facets)", "B (facets)"},
              {},
              {}};
  for (const auto& [name, op] : ops) {
    table.header.push_back(std::string(name) + " 1 thread (ms)");
    table.header.push_back(std::string(name) + " all (ms)");
  }
  table.header.push_back("facets dilate / erode / open / close");
  table.header.push_back("erode / dilate (1 thread)");
  for (const auto& [a, b_full] : pairs) {
    const Operand b{b_full.name + " x" + fixed(kMorphologyScale, 2),
                    scaled(b_full.mesh, kMorphologyScale)};
    std::cerr << "  morphology: " << a.name << " by " << b.name << '\n';
    std::vector<std::string> row{operand_cell(a), operand_cell(b)};
    std::string facets;
    std::vector<double> one_thread;
    for (const auto& [name, op] : ops) {
      std::string cell;
      for (int threads : {1, 0}) {
        const Timing t = time_median(
            [&] { cell = result_cell(op(a.mesh, b.mesh, {.threads = threads})); }, settings);
        row.push_back(ms(t.median_ms));
        if (threads == 1) one_thread.push_back(t.median_ms);
      }
      facets += (facets.empty() ? "" : " / ") + cell;
    }
    row.push_back(facets);
    row.push_back(ratio(one_thread[1] / one_thread[0]));
    table.rows.push_back(row);
  }
  table.notes.push_back(
      "Median times in milliseconds, warm-up excluded; `morph::dilate`, `morph::erode`, "
      "`morph::open`, `morph::close` with `threads = 1` and `threads = 0` (all cores), the "
      "result's mesh not copied. No hull route here.");
  report.table(table);
}

// ---------------------------------------------------------------------------------------
// Scaling

struct ScalingCase {
  std::string series;
  int parameter = 0;  // icosphere level, UV sphere n or number of random points
  Mesh a;
  Mesh b;
};

// Series names, also the keys of --peak-case.
const char* const kSameLevel = "icosphere L + rotated icosphere L";
const char* const kFixedSmall = "icosphere L + icosphere 1";
const char* const kRandom = "random n + random n";

ScalingCase make_case(const std::string& series, int parameter) {
  if (series == kSameLevel) {
    Mesh a = morph::make_icosphere(1.0, parameter);
    Mesh b = rotated(a, kRotationAngle);
    return {series, parameter, std::move(a), std::move(b)};
  }
  if (series == kFixedSmall)
    return {series, parameter, morph::make_icosphere(1.0, parameter),
            morph::make_icosphere(0.5, 1)};
  if (series == kRandom)
    return {series, parameter, random_polytope(parameter, kSeedA),
            random_polytope(parameter, kSeedB)};
  throw std::runtime_error("unknown scaling series: " + series);
}

struct ScalingPlan {
  std::string series;
  std::vector<int> parameters;
};

std::vector<ScalingPlan> scaling_plan(bool full) {
  if (full)
    return {{kSameLevel, {1, 2, 3, 4, 5, 6, 7}},
            {kFixedSmall, {1, 2, 3, 4, 5, 6, 7}},
            {kRandom, {50, 200, 800, 3200, 12800, 51200, 160000}}};
  return {{kSameLevel, {1, 2, 3, 4, 5}},
          {kFixedSmall, {1, 2, 3, 4, 5}},
          {kRandom, {50, 200, 800, 3200, 12800}}};
}

// Least-squares slope of log(y) against log(x).
double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = x.size();
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// The log-log slope of a series' times over its cases of >= 1000 input facets (below that,
// fixed costs dominate); none with fewer than two such cases.
std::optional<double> series_slope(const std::vector<double>& inputs,
                                   const std::vector<double>& times) {
  std::vector<double> fx, fy;
  for (std::size_t i = 0; i < inputs.size(); ++i)
    if (inputs[i] >= 1000) fx.push_back(inputs[i]), fy.push_back(times[i]);
  if (fx.size() < 2) return std::nullopt;
  return loglog_slope(fx, fy);
}

// Peak memory of one case measured in a fresh process (this program with --peak-case), so
// that nothing measured before (the hull route, other cases) counts.
std::string peak_memory(const std::string& series, int parameter) {
  char exe[4096];
  const ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (len <= 0) return "unavailable";
  exe[len] = '\0';
  const std::string command =
      "'" + std::string(exe) + "' --peak-case '" + series + "' " + std::to_string(parameter);
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return "unavailable";
  long before = 0, after = 0;
  const int got = std::fscanf(pipe, "%ld %ld", &before, &after);
  pclose(pipe);
  if (got != 2) return "unavailable";
  return fixed(after / 1024.0, 0) +
         " MiB peak resident (operands alone: " + fixed(before / 1024.0, 0) + " MiB)";
}

// Repeats one libmorph sum for a while, for a profiler to sample.
int run_loop(const Settings& settings, const std::string& a_file, const std::string& b_file,
             double seconds, int threads) {
  const Mesh a = morph::read_mesh(settings.samples / a_file);
  Mesh b = b_file == "rotated" ? rotated(a, kRotationAngle)
                               : morph::read_mesh(settings.samples / b_file);
  const auto op = settings.loop_op == "erode"   ? &morph::erode
                  : settings.loop_op == "open"  ? &morph::open
                  : settings.loop_op == "close" ? &morph::close
                                                : nullptr;
  if (!op && settings.loop_op != "sum")
    throw std::runtime_error("unknown --op " + settings.loop_op);
  if (op) b = scaled(b, kMorphologyScale);
  const auto start = Clock::now();
  int runs = 0;
  Counts out;
  while (milliseconds_since(start) < seconds * 1000.0) {
    if (op) {
      const auto r = op(a, b, {.threads = threads});
      out = {r.mesh.n_vertices(), r.mesh.n_faces()};
    } else {
      out = libmorph_sum(a, b, threads);
    }
    ++runs;
  }
  std::printf("%d runs, %.3f ms each, %zu vertices, %zu facets\n", runs,
              milliseconds_since(start) / runs, out.vertices, out.facets);
  return 0;
}

int run_peak_case(const std::string& series, int parameter) {
  const ScalingCase c = make_case(series, parameter);
  const long before = peak_rss_kib();
  const Counts out = libmorph_sum(c.a, c.b, 0);
  std::printf("%ld %ld %zu\n", before, peak_rss_kib(), out.facets);
  return 0;
}

void run_scaling(const Settings& settings, Report& report) {
  Table table{
      std::string("Scaling: A (+) B against input size") +
          (settings.full_scaling ? "" : " (quick; --scaling for the full range)"),
      "scaling.csv",
      {"series", "parameter", "input facets", "output facets", "1 thread (ms)", "all threads (ms)"},
      {},
      {}};
  Settings few = settings;  // large cases: no more repetitions than needed
  few.max_reps = 5;
  std::vector<std::string> slopes;
  std::string last_series;
  int last_parameter = 0;
  for (const auto& plan : scaling_plan(settings.full_scaling)) {
    std::vector<double> inputs, times;
    for (int parameter : plan.parameters) {
      std::cerr << "  scaling: " << plan.series << ", " << parameter << '\n';
      const ScalingCase c = make_case(plan.series, parameter);
      const std::size_t input = c.a.n_faces() + c.b.n_faces();
      Counts out;
      const Timing one = time_median([&] { out = libmorph_sum(c.a, c.b, 1); }, few);
      const Timing all = time_median([&] { out = libmorph_sum(c.a, c.b, 0); }, few);
      table.rows.push_back({plan.series, std::to_string(parameter), std::to_string(input),
                            std::to_string(out.facets), ms(one.median_ms), ms(all.median_ms)});
      inputs.push_back(static_cast<double>(input));
      times.push_back(one.median_ms);
    }
    if (const auto slope = series_slope(inputs, times))
      slopes.push_back("- " + plan.series + ": log-log slope " + fixed(*slope, 2) +
                       " (1 thread, inputs >= 1000 facets)");
    last_series = plan.series;
    last_parameter = plan.parameters.back();
  }
  table.notes = slopes;
  // Peak memory of the largest case of the series with the most input facets.
  std::size_t largest = 0;
  for (const auto& row : table.rows)
    if (std::stoul(row[2]) > largest)
      largest = std::stoul(row[2]), last_series = row[0], last_parameter = std::stoi(row[1]);
  table.notes.push_back(
      "- peak memory of the largest case (" + last_series + ", " + std::to_string(last_parameter) +
      ", all threads, fresh process): " + peak_memory(last_series, last_parameter));
  report.table(table);
}

// ---------------------------------------------------------------------------------------
// Morphology scaling: the four operations against input size, each pair's dilation timed in
// the same run, so that erosion, opening and closing read as multiples of it and their growth
// as log-log slopes (the morphology issue asks them to be linear, like the dilation). An
// opening is an erosion followed by a dilation, (A (-) B) (+) B: that second dilation is timed
// on its own too (of the eroded mesh), since it bounds how close an opening can come to the
// dilation A (+) B whatever its erosion costs.

// Series names. B is scaled so that it fits inside A and every erosion is a solid.
const char* const kMorphSameLevel = "icosphere L by 0.25 rotated icosphere L";
const char* const kMorphFixedSmall = "icosphere L by icosphere(0.25, 1)";
const char* const kMorphUv = "UV sphere n by 0.25 snub dodecahedron";
const char* const kMorphRandom = "random n by 0.25 random n";

ScalingCase make_morph_case(const std::string& series, int parameter) {
  if (series == kMorphSameLevel) {
    Mesh a = morph::make_icosphere(1.0, parameter);
    Mesh b = scaled(rotated(a, kRotationAngle), kMorphologyScale);
    return {series, parameter, std::move(a), std::move(b)};
  }
  if (series == kMorphFixedSmall)
    return {series, parameter, morph::make_icosphere(1.0, parameter),
            morph::make_icosphere(kMorphologyScale, 1)};
  if (series == kMorphUv)
    return {series, parameter, morph::make_uv_sphere(1.0, parameter),
            morph::make_snub_dodecahedron(kMorphologyScale)};
  if (series == kMorphRandom)
    return {series, parameter, random_polytope(parameter, kSeedA),
            scaled(random_polytope(parameter, kSeedB), kMorphologyScale)};
  throw std::runtime_error("unknown morphology scaling series: " + series);
}

std::vector<ScalingPlan> morph_scaling_plan(bool full) {
  if (full)
    return {{kMorphSameLevel, {1, 2, 3, 4, 5, 6, 7}},
            {kMorphFixedSmall, {1, 2, 3, 4, 5, 6, 7}},
            {kMorphUv, {10, 20, 40, 80, 160, 320, 512}},
            {kMorphRandom, {50, 200, 800, 3200, 12800, 51200, 160000}}};
  return {{kMorphSameLevel, {1, 2, 3, 4, 5}},
          {kMorphFixedSmall, {1, 2, 3, 4, 5}},
          {kMorphUv, {10, 20, 40, 80, 160}},
          {kMorphRandom, {50, 200, 800, 3200, 12800}}};
}

void run_morph_scaling(const Settings& settings, Report& report) {
  using Op = morph::MorphResult (*)(const Mesh&, const Mesh&, const morph::MorphologyOptions&);
  const std::pair<const char*, Op> ops[] = {{"dilate", &morph::dilate},
                                            {"erode", &morph::erode},
                                            {"open", &morph::open},
                                            {"close", &morph::close}};
  Table table{std::string("Morphology scaling: the four operations against input size") +
                  (settings.full_scaling ? "" : " (quick; --scaling for the full range)"),
              "morphology_scaling.csv",
              {"series", "parameter", "input facets", "facets dilate / erode / open / close"},
              {},
              {}};
  for (const auto& [name, op] : ops) table.header.push_back(std::string(name) + " 1 thread (ms)");
  table.header.push_back("erode all threads (ms)");
  table.header.push_back("dilate (A - B) by B, 1 thread (ms)");
  table.header.push_back("erode / dilate");
  table.header.push_back("open / dilate");
  Settings few = settings;  // large cases: no more repetitions than needed
  few.max_reps = 5;
  for (const auto& plan : morph_scaling_plan(settings.full_scaling)) {
    std::vector<double> inputs;
    std::vector<std::vector<double>> times(std::size(ops));
    std::vector<double> second_step;  // the opening's dilation of the eroded mesh
    for (int parameter : plan.parameters) {
      std::cerr << "  morphology scaling: " << plan.series << ", " << parameter << '\n';
      const ScalingCase c = make_morph_case(plan.series, parameter);
      const std::size_t input = c.a.n_faces() + c.b.n_faces();
      std::vector<std::string> row{plan.series, std::to_string(parameter), std::to_string(input),
                                   ""};
      std::string facets;
      for (std::size_t k = 0; k < std::size(ops); ++k) {
        std::string cell;
        const Op op = ops[k].second;
        const Timing t =
            time_median([&] { cell = result_cell(op(c.a, c.b, {.threads = 1})); }, few);
        row.push_back(ms(t.median_ms));
        times[k].push_back(t.median_ms);
        facets += (facets.empty() ? "" : " / ") + cell;
      }
      row[3] = facets;
      const Timing all = time_median([&] { morph::erode(c.a, c.b, {.threads = 0}); }, few);
      row.push_back(ms(all.median_ms));
      // The opening's second step alone: the eroded mesh dilated by B.
      const Mesh eroded = morph::erode(c.a, c.b, {.threads = 1}).mesh;
      const Timing second =
          eroded.n_faces() == 0
              ? Timing{}
              : time_median([&] { morph::dilate(eroded, c.b, {.threads = 1}); }, few);
      row.push_back(eroded.n_faces() == 0 ? "-" : ms(second.median_ms));
      second_step.push_back(second.median_ms);
      row.push_back(ratio(times[1].back() / times[0].back()));
      row.push_back(ratio(times[2].back() / times[0].back()));
      table.rows.push_back(row);
      inputs.push_back(static_cast<double>(input));
    }
    std::string slopes = "- " + plan.series + ": log-log slope";
    for (std::size_t k = 0; k < std::size(ops); ++k)
      if (const auto slope = series_slope(inputs, times[k]))
        slopes += std::string(k ? ", " : " ") + ops[k].first + " " + fixed(*slope, 2);
    table.notes.push_back(slopes + " (1 thread, inputs >= 1000 facets)");
    // What the opening's own dilation takes of the plain dilation's time, at the largest size.
    if (!second_step.empty() && times[0].back() > 0)
      table.notes.push_back("- " + plan.series +
                            ", largest: the opening's dilation of A - B alone takes " +
                            ratio(second_step.back() / times[0].back()) + " the time of A (+) B");
  }
  table.notes.push_back(
      "Median times in milliseconds, warm-up excluded, at most 5 repetitions; `morph::dilate`, "
      "`morph::erode`, `morph::open`, `morph::close` with `threads = 1`, and the erosion with "
      "`threads = 0` (all cores). The ratios divide 1-thread times of the same run. \"dilate "
      "(A - B) by B\" times `morph::dilate` of the eroded mesh: the step an opening takes after "
      "its erosion (the opening dilates the exact eroded polytope, without reading a mesh).");
  report.table(table);
}

// ---------------------------------------------------------------------------------------
// Machine

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  double one = 0, five = 0, fifteen = 0;
  in >> one >> five >> fifteen;
  return fixed(one, 2) + " " + fixed(five, 2) + " " + fixed(fifteen, 2);
}

bool g_malloc_defaults = false;  // --malloc-defaults

std::string machine() {
  std::ostringstream out;
  out << "Machine: " << cpu_model() << ", " << std::thread::hardware_concurrency()
      << " hardware threads (nproc " << sysconf(_SC_NPROCESSORS_ONLN) << "); load average at start "
      << load_average() << "; allocator: "
      << (g_malloc_defaults ? "glibc defaults (--malloc-defaults)"
                            : "freed memory kept for reuse (glibc trim threshold 64 MB, mmap "
                              "threshold 32 MB, as in the apps)")
      << "\n\n";
  return out.str();
}

void usage(std::ostream& out) {
  out << "usage: morph-bench [--table1] [--morphology] [--scaling] [--all]\n"
         "                   [--csv DIR] [--markdown FILE] [--samples DIR] [--budget SECONDS]\n"
         "                   [--filter TEXT] [--malloc-defaults]\n"
         "       morph-bench [--samples DIR] [--op OP] --loop A.off B.off|rotated SECONDS "
         "[THREADS]\n"
         "  no selection: Table 1, morphology and a quick scaling run\n";
}

}  // namespace

int main(int argc, char** argv) {
  try {
    Settings settings;
    const std::vector<std::string> args(argv + 1, argv + argc);
    // Before any allocation of either route: both are timed with the same allocator settings.
    g_malloc_defaults = std::find(args.begin(), args.end(), "--malloc-defaults") != args.end();
    if (!g_malloc_defaults) morph::cli::keep_freed_memory();
    if (args.size() == 3 && args[0] == "--peak-case")
      return run_peak_case(args[1], std::stoi(args[2]));
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& arg = args[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= args.size()) throw std::runtime_error(arg + " needs a value");
        return args[++i];
      };
      if (arg == "--table1")
        settings.table1 = true;
      else if (arg == "--morphology")
        settings.morphology = true;
      else if (arg == "--scaling")
        settings.scaling = settings.full_scaling = true;
      else if (arg == "--all")
        settings.table1 = settings.morphology = settings.scaling = settings.full_scaling = true;
      else if (arg == "--csv")
        settings.csv_dir = value();
      else if (arg == "--markdown")
        settings.markdown = value();
      else if (arg == "--samples")
        settings.samples = value();
      else if (arg == "--budget")
        settings.budget_seconds = std::stod(value());
      else if (arg == "--filter")
        settings.filter = value();
      else if (arg == "--malloc-defaults")
        continue;  // handled above
      else if (arg == "--op")
        settings.loop_op = value();
      else if (arg == "--loop") {
        const std::string a = value(), b = value();
        const double seconds = std::stod(value());
        const int threads = i + 1 < args.size() && args[i + 1][0] != '-' ? std::stoi(value()) : 1;
        return run_loop(settings, a, b, seconds, threads);
      } else if (arg == "--help" || arg == "-h")
        return usage(std::cout), 0;
      else
        throw std::runtime_error("unknown option " + arg);
    }
    if (!settings.table1 && !settings.morphology && !settings.scaling)
      settings.table1 = settings.morphology = settings.scaling = true;
    if (!settings.csv_dir.empty()) std::filesystem::create_directories(settings.csv_dir);

    Report report(settings);
    report.text(machine());
    if (settings.table1 || settings.morphology) {
      const auto pairs = table1_pairs(settings);
      if (settings.table1) run_table1(pairs, settings, report);
      if (settings.morphology) run_morphology(pairs, settings, report);
    }
    if (settings.scaling) {
      run_scaling(settings, report);
      run_morph_scaling(settings, report);
    }
    report.text("Load average at end " + load_average() + "\n");
    report.finish();
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "morph-bench: " << e.what() << '\n';
    usage(std::cerr);
    return 1;
  }
}
