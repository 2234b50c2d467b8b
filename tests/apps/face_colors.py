#!/usr/bin/env python3
"""Prints the face colours of an ASCII OFF or PLY mesh as one JSON object
{"faces": N, "colors": {"r g b": count, ...}} (faces without a colour are not counted
in "colors"). Used by the CLI tests to check --label-facets independently of libmorph."""
import json
import sys


def tokens_without_comments(lines):
    for line in lines:
        line = line.split("#", 1)[0].strip()
        if line:
            yield line


def off_colors(text):
    lines = list(tokens_without_comments(text.splitlines()))
    if not lines[0].startswith("OFF"):
        raise SystemExit("not an OFF file")
    rest = lines[0][3:].split()
    header = rest if rest else lines[1].split()
    body = lines[1:] if rest else lines[2:]
    nv, nf = int(header[0]), int(header[1])
    colors = {}
    for line in body[nv:nv + nf]:
        values = line.split()
        n = int(values[0])
        extra = values[1 + n:]
        if len(extra) >= 3:
            key = " ".join(str(int(float(v))) for v in extra[:3])
            colors[key] = colors.get(key, 0) + 1
    return nf, colors


def ply_colors(data):
    header_end = data.index(b"end_header") + len(b"end_header")
    header = data[:header_end].decode("ascii").splitlines()
    if "format ascii 1.0" not in header:
        raise SystemExit("only ascii PLY is read here")
    nv = nf = 0
    element = None
    face_props = []
    for line in header:
        words = line.split()
        if words[:1] == ["element"]:
            element = words[1]
            if element == "vertex":
                nv = int(words[2])
            elif element == "face":
                nf = int(words[2])
        elif words[:1] == ["property"] and element == "face":
            face_props.append(words[-1])
    body = data[header_end:].decode("ascii").split("\n")
    body = [line for line in body if line.strip()]
    colors = {}
    for line in body[nv:nv + nf]:
        values = line.split()
        record = {}
        i = 0
        for prop in face_props:
            if prop in ("vertex_indices", "vertex_index"):
                n = int(values[i])
                i += 1 + n
            else:
                record[prop] = values[i]
                i += 1
        if all(c in record for c in ("red", "green", "blue")):
            key = " ".join(record[c] for c in ("red", "green", "blue"))
            colors[key] = colors.get(key, 0) + 1
    return nf, colors


def main():
    path = sys.argv[1]
    with open(path, "rb") as f:
        data = f.read()
    if path.lower().endswith(".ply"):
        nf, colors = ply_colors(data)
    else:
        nf, colors = off_colors(data.decode("ascii"))
    print(json.dumps({"faces": nf, "colors": colors}, sort_keys=True))


if __name__ == "__main__":
    main()
