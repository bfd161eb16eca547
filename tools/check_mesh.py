#!/usr/bin/env python3
"""Checks that an exported mesh is a closed, consistently wound surface.

Usage:
    python3 tools/check_mesh.py FILE.ply [--expect-volume V [--tolerance 0.005]] [--expect-euler 2]

Loads the mesh with trimesh (process=False, so nothing is merged by distance: only the
exporter's welding counts), prints vertices, faces, is_watertight, is_winding_consistent,
euler_number and volume, and exits 1 if the mesh is not watertight, its winding is inconsistent,
or its volume (relative tolerance, default 0.5 %) or Euler number differ from what was expected.
A closed surface of genus 0 (a planet without caves through it) has Euler number 2.

Works with any format trimesh reads (PLY, OBJ, GLB); pmc's PLY is the intended input.
Requirements: tools/requirements.txt (pip install -r tools/requirements.txt).
"""

import argparse
import sys


def main() -> int:
    parser = argparse.ArgumentParser(
        description="Check an exported mesh for watertightness, winding, volume and Euler number."
    )
    parser.add_argument("file", help="mesh file, usually a .ply written by pmc")
    parser.add_argument("--expect-volume", type=float, metavar="V", help="expected volume in cubic metres")
    parser.add_argument(
        "--tolerance",
        type=float,
        default=0.005,
        help="relative tolerance of --expect-volume (default 0.005 = 0.5%%)",
    )
    parser.add_argument("--expect-euler", type=int, metavar="X", help="expected Euler number (2 for a sphere)")
    args = parser.parse_args()

    try:
        import numpy as np
        import trimesh
    except ImportError as e:
        print(f"error: {e}; install the requirements with: pip install -r tools/requirements.txt", file=sys.stderr)
        return 2

    try:
        mesh = trimesh.load(args.file, process=False, force="mesh")
    except Exception as e:  # trimesh raises many kinds of errors for unreadable files
        print(f"error: cannot load {args.file}: {e}", file=sys.stderr)
        return 1

    # Volume relative to the centroid of the vertices: the same number, without the cancellation
    # that summing tetrahedra from the world origin suffers far from it (planet-centred metres).
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    if len(faces) == 0:
        print(f"{args.file}: vertices {len(vertices)}, faces 0")
        print("FAIL: the mesh has no faces")
        return 1
    centred = vertices - vertices.mean(axis=0)
    a, b, c = centred[faces[:, 0]], centred[faces[:, 1]], centred[faces[:, 2]]
    volume = float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)

    watertight = bool(mesh.is_watertight)
    winding = bool(mesh.is_winding_consistent)
    euler = int(mesh.euler_number)
    print(f"{args.file}:")
    print(f"  vertices              {len(vertices)}")
    print(f"  faces                 {len(faces)}")
    print(f"  is_watertight         {watertight}")
    print(f"  is_winding_consistent {winding}")
    print(f"  euler_number          {euler}")
    print(f"  volume                {volume:.6g}")

    failures = []
    if not watertight:
        failures.append("not watertight (some edge is not shared by exactly two faces)")
    if not winding:
        failures.append("winding is inconsistent (neighbouring faces disagree on orientation)")
    if volume <= 0.0 and watertight and winding:
        failures.append("volume is not positive: faces wind inward (expected counter-clockwise from outside)")
    if args.expect_volume is not None:
        rel = abs(volume - args.expect_volume) / max(abs(args.expect_volume), 1e-300)
        if rel > args.tolerance:
            failures.append(
                f"volume {volume:.6g} differs from expected {args.expect_volume:.6g} by {rel:.3%} "
                f"(tolerance {args.tolerance:.3%})"
            )
    if args.expect_euler is not None and euler != args.expect_euler:
        failures.append(f"euler number {euler}, expected {args.expect_euler}")

    for f in failures:
        print(f"FAIL: {f}")
    if not failures:
        print("OK")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
