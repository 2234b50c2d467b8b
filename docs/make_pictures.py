#!/usr/bin/python3
"""Draws the pictures of docs/ from the outputs of libmorph's apps.

    docs/make_pictures.py BUILD_DIR [--out docs/img]

BUILD_DIR is a configured and built libmorph tree (its apps/ holds mesh-dilate,
mesh-erode, mesh-open and mesh-close). The script runs the apps on samples/ into a
temporary directory, with --label-facets, reads the
coloured OFF files back and renders PNGs with matplotlib (mplot3d, flat shading by facet
normal, back faces culled, orthographic view). Needs Debian 12's python3-matplotlib.

The facet colours are read from the apps' palette in apps/common/cli.h, so the pictures
always match what --label-facets writes. The contributing-vertex picture is computed
here, independently of the library: the contributing vertex of B for a facet of A with
outward normal n is the vertex b of B maximising <n, b>.
"""

import argparse
import math
import os
import re
import subprocess
import sys
import tempfile

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.patches import Patch
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection
except ImportError as e:  # pragma: no cover
    sys.exit(f"make_pictures.py: {e}; install python3-matplotlib (Debian) and run with /usr/bin/python3")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SAMPLES = os.path.join(ROOT, "samples")

DPI = 100
GREY = (0.78, 0.80, 0.83)
EDGE_LINE = (0.15, 0.15, 0.18)
# Four colours for the contributing vertices, from the Okabe-Ito palette but not the
# three of the facet labels.
VERTEX_COLORS = [(86, 180, 233), (213, 94, 0), (204, 121, 167), (240, 228, 66)]


# ----------------------------------------------------------------- palette


def read_palette():
    """The --label-facets colours, from apps/common/cli.h (the single source)."""
    text = open(os.path.join(ROOT, "apps", "common", "cli.h")).read()
    palette = {}
    for kind, name in (("translated", "kTranslatedColor"), ("corner", "kCornerColor"), ("edge", "kEdgeColor")):
        m = re.search(name + r"\s*=\s*\{\s*(\d+)\s*,\s*(\d+)\s*,\s*(\d+)\s*\}", text)
        if not m:
            sys.exit(f"make_pictures.py: {name} not found in apps/common/cli.h")
        palette[kind] = tuple(int(c) for c in m.groups())
    return palette


# ----------------------------------------------------------------- meshes


class Mesh:
    def __init__(self, points, faces, colors=None):
        self.points = np.asarray(points, dtype=float)
        self.faces = faces  # lists of vertex indices, counter-clockwise about the outward normal
        self.colors = colors  # one (r, g, b) in 0..255 per face, or None

    def normals(self):
        """Unit Newell normals."""
        out = np.zeros((len(self.faces), 3))
        for i, f in enumerate(self.faces):
            p = self.points[f]
            q = np.roll(p, -1, axis=0)
            n = np.array([
                np.sum((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2])),
                np.sum((p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0])),
                np.sum((p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1])),
            ])
            out[i] = n / np.linalg.norm(n)
        return out

    def edges(self):
        seen = set()
        for f in self.faces:
            for k in range(len(f)):
                u, w = f[k], f[(k + 1) % len(f)]
                seen.add((min(u, w), max(u, w)))
        return sorted(seen)


def read_off(path):
    """OFF with optional 'r g b' (0..255) after each face, as the apps write it."""
    with open(path) as f:
        lines = [line.split("#", 1)[0].split() for line in f]
    lines = [t for t in lines if t]
    if lines[0][0] != "OFF":
        sys.exit(f"make_pictures.py: {path}: not an OFF file")
    header = lines[0][1:] or lines[1]
    start = 1 if lines[0][1:] else 2
    nv, nf = int(header[0]), int(header[1])
    points = [[float(x) for x in lines[start + i][:3]] for i in range(nv)]
    faces, colors = [], []
    for t in lines[start + nv:start + nv + nf]:
        k = int(t[0])
        faces.append([int(x) for x in t[1:1 + k]])
        rest = t[1 + k:]
        colors.append(tuple(int(c) for c in rest[:3]) if len(rest) >= 3 else None)
    return Mesh(points, faces, colors if all(c is not None for c in colors) and colors else None)


def write_off(path, mesh):
    with open(path, "w") as f:
        f.write(f"OFF\n{len(mesh.points)} {len(mesh.faces)} 0\n")
        for p in mesh.points:
            f.write("%.17g %.17g %.17g\n" % tuple(p))
        for face in mesh.faces:
            f.write(f"{len(face)} " + " ".join(str(v) for v in face) + "\n")


def rotated(mesh, axis, degrees):
    a = np.asarray(axis, dtype=float)
    a /= np.linalg.norm(a)
    t = math.radians(degrees)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    r = np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * (k @ k)
    return Mesh(mesh.points @ r.T, mesh.faces)


# ----------------------------------------------------------------- apps


class Apps:
    def __init__(self, build_dir, work_dir):
        self.bin = os.path.join(os.path.abspath(build_dir), "apps")
        self.work = work_dir
        for app in ("mesh-dilate", "mesh-erode", "mesh-open", "mesh-close"):
            if not os.access(os.path.join(self.bin, app), os.X_OK):
                sys.exit(f"make_pictures.py: {self.bin}/{app} not found; build it first "
                         f"(cmake --build {build_dir} --target {app})")

    def run(self, app, mesh, se, name, labels=True):
        """Runs `app mesh --se se` into the work directory and reads the result."""
        out = os.path.join(self.work, name + ".off")
        cmd = [os.path.join(self.bin, app), mesh, "--se", se, "-o", out, "--quiet"]
        if labels:
            cmd.append("--label-facets")
        print("  " + " ".join(os.path.relpath(c, ROOT) if c.startswith(ROOT) else c for c in cmd))
        subprocess.run(cmd, check=True)
        return read_off(out)


# ----------------------------------------------------------------- drawing


def view_vectors(elev, azim):
    """Unit vectors toward the viewer, up and right on the screen, for mplot3d's view."""
    e, a = math.radians(elev), math.radians(azim)
    eye = np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])
    right = np.array([-math.sin(a), math.cos(a), 0.0])
    up = np.cross(eye, right)
    return eye, up, right


def shade(rgb, normal, light):
    """Flat shading: ambient plus Lambert diffuse."""
    k = 0.5 + 0.5 * max(0.0, float(np.dot(normal, light)))
    return tuple(min(1.0, c / 255.0 * k) for c in rgb) if max(rgb) > 1 else tuple(min(1.0, c * k) for c in rgb)


def new_axes(fig, spec, elev, azim):
    ax = fig.add_subplot(spec, projection="3d")
    ax.set_proj_type("ortho")
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()
    ax.set_box_aspect((1, 1, 1))
    return ax


def set_extent(ax, radius, centre=(0, 0, 0)):
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
        setter(c - radius, c + radius)


def draw_mesh(ax, mesh, colors=None, line_width=0.4, ghost=None):
    """Draws the facets that face the viewer, flat shaded; `ghost` (a mesh) is drawn as a
    faint wireframe for scale."""
    eye, up, right = view_vectors(ax.elev, ax.azim)
    light = eye + 0.7 * up - 0.35 * right
    light /= np.linalg.norm(light)
    normals = mesh.normals()
    colors = colors or mesh.colors or [GREY] * len(mesh.faces)
    polys, fills = [], []
    for face, n, c in zip(mesh.faces, normals, colors):
        if np.dot(n, eye) <= 0:
            continue  # a back face of a convex solid: hidden
        polys.append(mesh.points[face])
        fills.append(shade(c, n, light))
    coll = Poly3DCollection(polys, facecolors=fills, edgecolors=EDGE_LINE, linewidths=line_width)
    ax.add_collection3d(coll)
    if ghost is not None:
        segs = [ghost.points[[u, w]] for u, w in ghost.edges()]
        ax.add_collection3d(Line3DCollection(segs, colors=[(0.3, 0.3, 0.35, 0.35)], linewidths=0.6,
                                             linestyles="dashed"))


def legend(fig, palette, kinds=("translated", "corner", "edge"), **kw):
    names = {"translated": "translated facets (facets of A)", "corner": "corner facets (facets of B)",
             "edge": "edge facets (edge of A ⊕ edge of B)"}
    handles = [Patch(facecolor=np.array(palette[k]) / 255.0, edgecolor=EDGE_LINE, label=names[k]) for k in kinds]
    fig.legend(handles=handles, frameon=False, **kw)


def caption(fig, ax, text, y, fontsize=10):
    """A caption centred on an axes horizontally, at height y of the figure (0..1)."""
    box = ax.get_position()
    fig.text((box.x0 + box.x1) / 2, y, text, ha="center", va="top", fontsize=fontsize)


def save(fig, path):
    fig.savefig(path, dpi=DPI, facecolor="white")
    plt.close(fig)
    print(f"  wrote {os.path.relpath(path, ROOT)} ({os.path.getsize(path) // 1024} KB)")


def radius_of(*meshes):
    return max(np.max(np.linalg.norm(m.points, axis=1)) for m in meshes)


# ----------------------------------------------------------------- pictures


def picture_readme(apps, palette, out_dir):
    """UV sphere (+) snub dodecahedron, beside its operands."""
    a_path = os.path.join(SAMPLES, "uvsphere_1600.off")
    b_path = os.path.join(SAMPLES, "snub_dodecahedron.off")
    s = apps.run("mesh-dilate", a_path, b_path, "readme")
    a, b = read_off(a_path), read_off(b_path)
    fig = plt.figure(figsize=(8, 4.2))
    grid = fig.add_gridspec(1, 3, width_ratios=[1, 1, 2], left=0, right=1, top=1, bottom=0.1, wspace=0)
    r = radius_of(s)
    for col, mesh, title, colors in ((0, a, "A: UV sphere", [palette["translated"]] * len(a.faces)),
                                     (1, b, "B: snub dodecahedron", [palette["corner"]] * len(b.faces))):
        ax = new_axes(fig, grid[0, col], 22, -58)
        draw_mesh(ax, mesh, colors=colors, line_width=0.15 if len(mesh.faces) > 500 else 0.5)
        set_extent(ax, 0.66 * r)  # the operands and the sum at the same scale
        caption(fig, ax, title, 0.38)
    ax = new_axes(fig, grid[0, 2], 22, -58)
    draw_mesh(ax, s, line_width=0.1)
    set_extent(ax, 0.66 * r)
    caption(fig, ax, "A ⊕ B", 0.135)
    fig.text(0.25, 0.55, "⊕", fontsize=18, ha="center", va="center")
    fig.text(0.5, 0.55, "=", fontsize=18, ha="center", va="center")
    legend(fig, palette, loc="lower center", ncol=3, fontsize=8.5, bbox_to_anchor=(0.5, 0.0))
    save(fig, os.path.join(out_dir, "readme.png"))


def picture_cube_tetrahedron(apps, palette, out_dir):
    """The paper's example, cube (+) tetrahedron: the sample tetrahedron, whose edges are
    parallel to the cube's facets, and the same tetrahedron turned."""
    cube_path = os.path.join(SAMPLES, "cube.off")
    tet_path = os.path.join(SAMPLES, "tetrahedron.off")
    tet = read_off(tet_path)
    turned = rotated(tet, (1, 2, 3), 25)
    turned_path = os.path.join(apps.work, "tetrahedron_turned.off")
    write_off(turned_path, turned)
    s1 = apps.run("mesh-dilate", cube_path, tet_path, "cube_tetrahedron")
    s2 = apps.run("mesh-dilate", cube_path, turned_path, "cube_tetrahedron_turned")
    cube = read_off(cube_path)
    fig = plt.figure(figsize=(8, 6))
    grid = fig.add_gridspec(2, 3, width_ratios=[1, 1, 1.6], left=0, right=1, top=1, bottom=0.06, wspace=0,
                            hspace=0)
    elev, azim = 28, 30
    rows = ((tet, s1, "B: tetrahedron (samples)", "A ⊕ B"), (turned, s2, "B′: B turned by 25°", "A ⊕ B′"))
    for row, (b, s, b_title, s_title) in enumerate(rows):
        y_text = 0.56 + 0.47 * (1 - row) - 0.47 * 0.22
        ax = new_axes(fig, grid[row, 0], elev, azim)
        draw_mesh(ax, cube, colors=[palette["translated"]] * len(cube.faces), line_width=0.8)
        set_extent(ax, 1.0)
        caption(fig, ax, "A: cube", y_text - 0.26)
        ax = new_axes(fig, grid[row, 1], elev, azim)
        draw_mesh(ax, b, colors=[palette["corner"]] * len(b.faces), line_width=0.8)
        set_extent(ax, 1.0)
        caption(fig, ax, b_title, y_text - 0.26)
        ax = new_axes(fig, grid[row, 2], elev, azim)
        draw_mesh(ax, s, line_width=0.8)
        set_extent(ax, 1.45)
        caption(fig, ax, f"{s_title}: {kinds_text(s, palette)}", y_text - 0.31, fontsize=9)
        fig.text(0.305, y_text - 0.145, "⊕", fontsize=16, ha="center", va="center")
        fig.text(0.615, y_text - 0.145, "=", fontsize=16, ha="center", va="center")
    legend(fig, palette, loc="lower center", ncol=3, fontsize=8.5, bbox_to_anchor=(0.5, 0.0))
    save(fig, os.path.join(out_dir, "cube_tetrahedron.png"))


def kinds_text(mesh, palette):
    count = {k: sum(1 for c in mesh.colors if c == palette[k]) for k in palette}
    return f"{count['translated']} translated,\n{count['corner']} corner, {count['edge']} edge facets"


def picture_morphology(apps, palette, out_dir):
    """Erosion, opening and closing of the cube by a small sphere."""
    a_path = os.path.join(SAMPLES, "cube.off")
    # B is sphere:r=0.2,level=2 written out as a file, so the picture shows exactly the
    # element used: samples/icosphere_320.off is that icosphere with radius 1.
    b = read_off(os.path.join(SAMPLES, "icosphere_320.off"))
    b.points *= 0.2
    se = os.path.join(apps.work, "sphere_r0.2.off")
    write_off(se, b)
    a = read_off(a_path)
    eroded = apps.run("mesh-erode", a_path, se, "eroded")
    opened = apps.run("mesh-open", a_path, se, "opened")
    closed = apps.run("mesh-close", a_path, se, "closed")
    dilated = apps.run("mesh-dilate", a_path, se, "dilated")
    fig = plt.figure(figsize=(8, 6))
    grid = fig.add_gridspec(2, 3, left=0, right=1, top=0.95, bottom=0.07, wspace=0, hspace=0.05)
    r = radius_of(dilated)
    panels = [
        (grid[0, 0], a, None, None, "A: cube, edge 1"),
        (grid[1, 0], b, [palette["corner"]] * len(b.faces), None, "B: sphere, r = 0.2"),
        (grid[0, 1], dilated, None, a, "dilation A ⊕ B"),
        (grid[0, 2], eroded, None, a, "erosion A ⊖ B"),
        (grid[1, 1], opened, None, a, "opening (A ⊖ B) ⊕ B"),
        (grid[1, 2], closed, None, a, "closing (A ⊕ B) ⊖ B = A"),
    ]
    for spec, mesh, colors, ghost, title in panels:
        ax = new_axes(fig, spec, 24, -56)
        draw_mesh(ax, mesh, colors=colors, line_width=0.3, ghost=ghost)
        set_extent(ax, 0.74 * r)
        ax.set_title(title, fontsize=10, y=0.9)
    legend(fig, palette, loc="lower center", ncol=3, fontsize=8.5, bbox_to_anchor=(0.5, 0.0))
    fig.text(0.5, 0.055, "dashed: A", ha="center", fontsize=8.5)
    save(fig, os.path.join(out_dir, "morphology.png"))


def picture_contributing_vertices(apps, palette, out_dir):
    """Facets of A coloured by their contributing vertex of B, B's Gauss map with A's
    normals on it, and A (+) B."""
    a_path = os.path.join(SAMPLES, "icosphere_320.off")
    tet = rotated(read_off(os.path.join(SAMPLES, "tetrahedron.off")), (1, 2, 3), 25)
    tet.points *= 0.6
    b_path = os.path.join(apps.work, "tetrahedron_small.off")
    write_off(b_path, tet)
    a = read_off(a_path)
    b = read_off(b_path)
    s = apps.run("mesh-dilate", a_path, b_path, "contributing")
    na = a.normals()
    support = na @ b.points.T  # <n_f, b_j>
    order = np.sort(support, axis=1)
    tie = order[:, -1] - order[:, -2] < 1e-12
    contributing = np.argmax(support, axis=1)
    colors = [GREY if t else VERTEX_COLORS[j] for j, t in zip(contributing, tie)]
    # Look along the bisector of two facet normals of B (an edge of B seen from outside,
    # tilted a little), so that all four regions of its Gauss map show.
    nb = b.normals()
    eye = nb[0] + nb[1] + 0.35 * nb[2]
    eye /= np.linalg.norm(eye)
    elev, azim = math.degrees(math.asin(eye[2])), math.degrees(math.atan2(eye[1], eye[0]))
    fig = plt.figure(figsize=(8, 6))
    grid = fig.add_gridspec(2, 2, left=0, right=1, top=0.98, bottom=0.0, wspace=0, hspace=0.0)
    # B with its vertices marked.
    ax = new_axes(fig, grid[0, 0], elev, azim)
    draw_mesh(ax, b, colors=[(0.88, 0.88, 0.9)] * len(b.faces), line_width=0.8)
    eye = view_vectors(elev, azim)[0]
    for j, p in enumerate(b.points):
        ax.scatter(*p, s=90, color=np.array(VERTEX_COLORS[j]) / 255.0, edgecolors="black", depthshade=False,
                   zorder=10, alpha=1.0 if np.dot(p, eye) > -0.2 else 0.5)
    set_extent(ax, 0.62)
    ax.set_title("B: a tetrahedron, its four vertices", fontsize=10, y=0.95)
    # B's Gauss map and A's normals.
    ax = new_axes(fig, grid[0, 1], elev, azim)
    draw_gauss_map(ax, b, na, colors, eye)
    set_extent(ax, 0.95)
    ax.set_title("Gauss map of B (arcs, facet normals ■),\nnormals of A (dots)", fontsize=10, y=0.93)
    # A coloured by contributing vertex.
    ax = new_axes(fig, grid[1, 0], elev, azim)
    draw_mesh(ax, a, colors=colors, line_width=0.3)
    set_extent(ax, 0.95)
    ax.set_title("A: each facet in the colour of its\ncontributing vertex of B", fontsize=10, y=0.93)
    ax = new_axes(fig, grid[1, 1], elev, azim)
    draw_mesh(ax, s, line_width=0.3)
    set_extent(ax, 0.95 + 0.55)
    ax.set_title("A ⊕ B: translated (blue), corner (orange),\nedge (green) facets", fontsize=10, y=0.93)
    save(fig, os.path.join(out_dir, "contributing_vertices.png"))


def draw_gauss_map(ax, b, points, point_colors, eye):
    """The unit sphere's outline, B's Gauss map arcs (front solid, back dotted) and
    `points` (unit normals) coloured, front side only."""
    t = np.linspace(0, 2 * math.pi, 200)
    _, up, right = view_vectors(ax.elev, ax.azim)
    circle = np.outer(np.cos(t), right) + np.outer(np.sin(t), up)
    ax.plot(circle[:, 0], circle[:, 1], circle[:, 2], color=(0.5, 0.5, 0.55), linewidth=0.8)
    nb = b.normals()
    # Each edge of B is an arc between the normals of its two facets.
    face_of_edge = {}
    for fi, f in enumerate(b.faces):
        for k in range(len(f)):
            face_of_edge.setdefault(tuple(sorted((f[k], f[(k + 1) % len(f)]))), []).append(fi)
    for fl, fr in face_of_edge.values():
        p, q = nb[fl], nb[fr]
        omega = math.acos(max(-1.0, min(1.0, float(np.dot(p, q)))))
        s = np.linspace(0, 1, 60)
        arc = (np.outer(np.sin((1 - s) * omega), p) + np.outer(np.sin(s * omega), q)) / math.sin(omega)
        front = arc @ eye >= 0
        for mask, style, alpha in ((front, "solid", 1.0), (~front, "dotted", 0.45)):
            seg = np.where(mask[:, None], arc, np.nan)
            ax.plot(seg[:, 0], seg[:, 1], seg[:, 2], color="black", linewidth=1.4, linestyle=style, alpha=alpha)
    for n in nb:
        if np.dot(n, eye) > 0:
            ax.scatter(*n, s=30, color="black", marker="s", depthshade=False)
    front = points @ eye > 0
    cols = np.array([np.array(c) / (255.0 if max(c) > 1 else 1.0) for c in point_colors])
    ax.scatter(points[front, 0], points[front, 1], points[front, 2], s=9, c=cols[front], edgecolors="none",
               depthshade=False)


# ----------------------------------------------------------------- main


def main():
    parser = argparse.ArgumentParser(description="Draw the pictures of docs/ from libmorph's apps.")
    parser.add_argument("build_dir", help="a built libmorph tree (holds apps/mesh-dilate, ...)")
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "img"), help="where the PNGs go")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    palette = read_palette()
    with tempfile.TemporaryDirectory(prefix="morph-pictures-") as work:
        apps = Apps(args.build_dir, work)
        for draw in (picture_readme, picture_cube_tetrahedron, picture_morphology, picture_contributing_vertices):
            print(" ".join(draw.__doc__.split()))
            draw(apps, palette, args.out)


if __name__ == "__main__":
    main()
