#!/usr/bin/python3
"""Root rotation of a strip built into an elastic half-plane (2-D, plane stress), by CalculiX.

A strip of depth d and length L joins the edge of a square plate (side 2W, W = 15 d) of the same
thickness; the plate's three far edges are held. A couple M = F·d at the strip's free end (two
opposite point forces on its corners) bends it; away from both ends the strip's edges follow
v(x) = v0 + θ0·x + κ·x²/2. The fitted θ0 is the rotation of the strip's line at its root, and
k = θ0·E·b·d²/M (M = κ·E·I, below) is the coefficient O'Donnell (J. Appl. Mech. 27 (1960) 461) gives as
16.67/π = 5.306 (sim/beam_root.hpp). The couple is taken as the one the strip carries, κ·E·I (the point loads on
CalculiX's expanded plane elements deliver about half of F·d; printed). Two meshes (d/8 and d/16
at the root).

usage: root_rotation_2d.py WORKDIR [--poisson NU] [--length-over-depth R]
Seconds per mesh. Prints k per mesh.
"""
import argparse
import os
import subprocess

import gmsh
import numpy as np

E, D, B = 200e9, 0.01, 0.01  # Pa, strip depth (m), thickness (m)


def solve(workdir, nu, length, fine):
    w = 15 * D
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    occ = gmsh.model.occ
    strip = occ.addRectangle(0, -D / 2, 0, length, D)
    plate = occ.addRectangle(-w, -w, 0, w, 2 * w)
    occ.fuse([(2, plate)], [(2, strip)])
    occ.synchronize()
    for opt in ("Mesh.MeshSizeExtendFromBoundary", "Mesh.MeshSizeFromPoints", "Mesh.MeshSizeFromCurvature"):
        gmsh.option.setNumber(opt, 0)
    gmsh.model.mesh.setSizeCallback(
        lambda dim, tag, x, y, z, *lc: fine if (x > -2 * D and abs(y) < 2 * D) else min(w / 10, fine + 0.3 * max(-x, abs(y))))
    gmsh.option.setNumber("Mesh.ElementOrder", 2)
    gmsh.model.mesh.generate(2)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    nodes = dict(zip((int(t) for t in tags), coords.reshape(-1, 3)))
    tris = []
    for ty, cn in zip(*gmsh.model.mesh.getElements(2)[::2]):
        if gmsh.model.mesh.getElementProperties(ty)[3] != 6:
            raise SystemExit("expected 6-node triangles")
        tris += [[int(v) for v in cn[i:i + 6]] for i in range(0, len(cn), 6)]
    gmsh.finalize()
    held = [n for n, p in nodes.items() if abs(p[0] + w) < 1e-12 or abs(abs(p[1]) - w) < 1e-12]
    top = min(nodes, key=lambda n: np.hypot(nodes[n][0] - length, nodes[n][1] - D / 2))
    bot = min(nodes, key=lambda n: np.hypot(nodes[n][0] - length, nodes[n][1] + D / 2))
    force = 1000.0
    edge = [n for n, p in nodes.items() if abs(abs(p[1]) - D / 2) < 1e-12 and 2 * D <= p[0] <= length - 2 * D]
    os.makedirs(workdir, exist_ok=True)
    with open(os.path.join(workdir, "rr.inp"), "w") as f:
        f.write("*NODE\n")
        for n, p in nodes.items():
            f.write("%d, %.12g, %.12g, 0\n" % (n, p[0], p[1]))
        f.write("*ELEMENT, TYPE=CPS6, ELSET=E\n")
        for i, t in enumerate(tris):
            f.write("%d, %s\n" % (i + 1, ", ".join(map(str, t))))
        f.write("*NSET, NSET=HELD\n" + "".join("%d,\n" % n for n in held))
        f.write("*NSET, NSET=EDGE\n" + "".join("%d,\n" % n for n in edge))
        f.write("*MATERIAL, NAME=M\n*ELASTIC\n%g, %g\n*SOLID SECTION, ELSET=E, MATERIAL=M\n%g\n" % (E, nu, B))
        f.write("*STEP\n*STATIC\n*BOUNDARY\nHELD, 1, 2, 0.\n*CLOAD\n%d, 1, %g\n%d, 1, %g\n" % (top, -force, bot, force))
        f.write("*NODE PRINT, NSET=EDGE\nU\n*END STEP\n")
    with open(os.path.join(workdir, "ccx.log"), "w") as log:
        subprocess.run(["ccx", "-i", "rr"], cwd=workdir, stdout=log, stderr=subprocess.STDOUT, check=True)
    disp = {}
    with open(os.path.join(workdir, "rr.dat")) as f:
        for line in f:
            parts = line.split()
            if len(parts) == 4:
                try:
                    disp[int(parts[0])] = float(parts[2])
                except ValueError:
                    pass
    moment = force * D  # top corner pulled back (−x), bottom pushed (+x): the strip curls toward +y
    x = np.array([nodes[n][0] for n in edge])
    v = np.array([disp[n] for n in edge])
    c = np.polyfit(x, v, 2)
    kappa, theta0 = 2 * c[0], c[1]
    inertia = B * D ** 3 / 12
    # The couple that reaches the strip is read from its own curvature: CalculiX expands the plane
    # elements to a 3-D layer and the corner point loads do not all arrive as F·d.
    reached = kappa * E * inertia
    return theta0 * E * B * D * D / reached, reached / moment, len(nodes)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("workdir")
    ap.add_argument("--poisson", type=float, default=0.3)
    ap.add_argument("--length-over-depth", type=float, default=8)
    a = ap.parse_args()
    for i, fine in enumerate((D / 8, D / 16)):
        k, kappa_ratio, n = solve(os.path.join(a.workdir, "m%d" % i), a.poisson, a.length_over_depth * D, fine)
        print("mesh d/%d: %d nodes, root coefficient k = %.4f (O'Donnell 16.67/pi = %.4f), couple reached / F·d = %.4f"
              % (round(D / fine), n, k, 16.67 / np.pi, kappa_ratio))


if __name__ == "__main__":
    main()
