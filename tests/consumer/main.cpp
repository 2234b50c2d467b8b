// A program outside libmorph that uses the installed package: it dilates, erodes and
// opens a box by a smaller box and checks the results against their known sizes.
// Exit status 0 when every check holds, 1 otherwise. Also the example of docs/library.md.
#include <morph/morph.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace {

int failures = 0;

void check(bool ok, const std::string& what) {
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
  if (!ok) ++failures;
}

bool near(double x, double y) { return std::abs(x - y) <= 1e-12 * std::max(1.0, std::abs(y)); }

}  // namespace

int main() {
  const morph::Mesh a = morph::make_box(1, 2, 3);  // centred on the origin
  const morph::Mesh b = morph::make_structuring_element("box:0.5,0.5,0.5");

  morph::MorphologyOptions options;
  options.threads = 2;

  // Dilation: the box grows by 0.5 in each direction; its 6 facets are translated facets.
  const morph::MorphResult d = morph::dilate(a, b, options);
  check(d.mesh.n_vertices() == 8 && d.mesh.n_faces() == 6,
        "dilation is a box (8 vertices, 6 facets)");
  check(near(morph::signed_volume(d.mesh), 1.5 * 2.5 * 3.5), "dilation volume 1.5 * 2.5 * 3.5");
  check(d.origins.size() == d.mesh.n_faces(), "one facet origin per facet");
  bool translated = true;
  for (const morph::FacetOrigin& o : d.origins)
    translated = translated && o.kind == morph::FacetKind::translated;
  check(translated, "every facet of a box (+) box is a translated facet");

  // Erosion: the box shrinks by 0.5 in each direction.
  const morph::MorphResult e = morph::erode(a, b, options);
  check(!e.is_empty() && near(morph::signed_volume(e.mesh), 0.5 * 1.5 * 2.5),
        "erosion volume 0.5 * 1.5 * 2.5");

  // Opening a box by a smaller box gives the box back.
  const morph::MorphResult o = morph::open(a, b, options);
  check(!o.is_empty() && near(morph::signed_volume(o.mesh), 6.0), "opening gives the box back");

  // An element that does not fit: the erosion is empty, not an error.
  const morph::MorphResult none = morph::erode(b, a, options);
  check(none.empty_reason == morph::EmptyReason::empty,
        "eroding the small box by the big one is empty");

  // Errors are typed: an open mesh (one facet removed) is an invalid_mesh, a morph::error.
  morph::Mesh open_box = a;
  open_box.delete_face(*open_box.faces_begin());
  open_box.garbage_collection();
  try {
    morph::dilate(open_box, b);
    check(false, "an open mesh is rejected");
  } catch (const morph::invalid_mesh& err) {
    check(std::string(err.what()).find("A") != std::string::npos,
          std::string("invalid_mesh: ") + err.what());
  }

  std::printf("libmorph %s: %s\n", morph::kVersion,
              failures == 0 ? "all checks passed" : "checks failed");
  return failures == 0 ? 0 : 1;
}
