#!/usr/bin/python3
"""make bench: the same 256^3 sphere field meshed by scikit-image's marching_cubes and
OpenVDB's volumeToMesh (Debian's python3-skimage and python3-openvdb), for comparison with
argil's block mesher. Prints median seconds of 3 runs for each; a missing package is said."""
import sys
import time

import numpy as np


def field(n=256, r=100.0):
    c = (n - 1) / 2.0
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
    return (r - np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2)).astype(np.float32)


def median_time(fn, runs=3):
    times = []
    out = None
    for _ in range(runs):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    times.sort()
    return times[len(times) // 2], out


def main():
    f = field()
    try:
        from skimage import measure
        t, (verts, faces, _, _) = median_time(lambda: measure.marching_cubes(f, level=0.0))
        print(f"  scikit-image marching_cubes, 256^3 sphere r=100: {t:.3f} s ({len(faces)} triangles)")
    except ImportError:
        print("  scikit-image not installed (python3-skimage): skipped")
    try:
        import pyopenvdb as vdb
        grid = vdb.FloatGrid(background=-1000.0)
        grid.copyFromArray(f)
        t, (points, tris, quads) = median_time(lambda: grid.convertToPolygons(isovalue=0.0, adaptivity=0.0))
        print(f"  OpenVDB volumeToMesh (convertToPolygons), same field: {t:.3f} s "
              f"({len(tris) + 2 * len(quads)} triangles)")
    except ImportError:
        print("  OpenVDB not installed (python3-openvdb): skipped")
    return 0


if __name__ == "__main__":
    sys.exit(main())
