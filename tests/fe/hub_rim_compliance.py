#!/usr/bin/python3
"""How much the hub, the rim and the beam roots' joints soften a hub-spoke body (CalculiX).

The beam model and both FE checks (`ftsim design --fe-check`, independent_fe.py) keep the hub and
the rim rigid and clamp the beams' end faces. This script meshes the body as drawn instead: a hub
disk (radius hub_radius_m), the beams, and a rim ring (rim_radius_m to rim_radius_m + the larger
beam section side), all as deep as the beams, fused into one elastic solid; the load enters
through a rigid flange on the hub's top face and the rim's bottom face is clamped (the mounting
face). It also solves the members-only body (beam end faces on rigid bodies) with the same
10-node tetrahedra, so the ratio of the two is the hub/rim/joint compliance alone, not a
difference of element types. A floating rim joint is not modelled (the rim ends are bonded).

usage: hub_rim_compliance.py DESIGN.json WORKDIR [--size-m S] [--refine R] [--out RESULT.json]
                             [--step BODY.step]
With --step the body as drawn is the STEP file `ftsim design --step` wrote (its mounting holes
included) instead of the script's own drawing.
DESIGN.json: `ftsim design --eval hub-spoke:… --json` (or `--sensor … --json`). Two meshes, the
second `--refine` times finer, so the figures' mesh dependence is visible. Minutes, not seconds:
a script, not a ctest.
"""
import argparse
import json
import math
import os
import subprocess
import time

import gmsh
import numpy as np

from independent_fe import AXES, DELTA, end_face_bodies, members_from_parameters, read_reactions

# gmsh's 10-node tetrahedron: edges (0,1),(1,2),(2,0),(0,3),(2,3),(1,3); CalculiX's C3D10:
# (1,2),(2,3),(3,1),(1,4),(2,4),(3,4): the last two mid-edge nodes swap.
GMSH_TO_CCX_TET = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]


def mesh_tets(add_geometry, fine, coarse, region, straight=False):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("body")
    add_geometry(gmsh.model.occ)
    gmsh.model.occ.synchronize()
    for opt in ("Mesh.MeshSizeExtendFromBoundary", "Mesh.MeshSizeFromPoints", "Mesh.MeshSizeFromCurvature"):
        gmsh.option.setNumber(opt, 0)
    gmsh.model.mesh.setSizeCallback(lambda dim, tag, x, y, z, *lc: fine if region(x, y, z) else coarse)
    gmsh.option.setNumber("Mesh.ElementOrder", 2)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
    # Mid-edge nodes on the straight edge: tets at the imported body's small imprinted gauge pads
    # and hole edges otherwise fold when their nodes are moved onto the curved faces.
    gmsh.option.setNumber("Mesh.SecondOrderLinear", 1 if straight else 0)
    gmsh.model.mesh.generate(3)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    nodes = dict(zip((int(t) for t in tags), coords.reshape(-1, 3)))
    tets = []
    types, _, conn = gmsh.model.mesh.getElements(3)
    for ty, cn in zip(types, conn):
        name, _, _, nn, _, _ = gmsh.model.mesh.getElementProperties(ty)
        if nn != 10:
            raise SystemExit("expected 10-node tetrahedra, got " + name)
        tets += [[int(cn[i + k]) for k in GMSH_TO_CCX_TET] for i in range(0, len(cn), 10)]
    gmsh.finalize()
    return nodes, tets


def write_and_solve(workdir, nodes, tets, material, platform, clamped):
    """Platform nodes on one rigid body moved by unit displacements; clamped nodes held."""
    os.makedirs(workdir, exist_ok=True)
    ref = max(nodes) + 100
    path = os.path.join(workdir, "hr.inp")
    with open(path, "w") as f:
        f.write("** hub/rim compliance (tests/fe/hub_rim_compliance.py), SI units\n*NODE\n")
        for nid, p in nodes.items():
            q = [0.0 if abs(v) < 1e-15 else v for v in p]
            f.write("%d, %.12g, %.12g, %.12g\n" % (nid, *q))
        f.write("%d, 0, 0, 0\n%d, 0, 0, 0\n" % (ref, ref + 1))
        f.write("*ELEMENT, TYPE=C3D10, ELSET=SOLID\n")
        for i, t in enumerate(tets):
            f.write("%d, %s\n" % (i + 1, ", ".join(map(str, t))))
        for name, ids in (("PLATF", platform), ("CLAMP", clamped)):
            f.write("*NSET, NSET=%s\n" % name)
            for k in range(0, len(ids), 12):
                f.write(", ".join(map(str, ids[k:k + 12])) + ",\n")
        f.write("*NSET, NSET=PLAT\n%d, %d\n" % (ref, ref + 1))
        f.write("*MATERIAL, NAME=M\n*ELASTIC\n%.10g, %.6g\n" % (material["e_pa"], material["poisson"]))
        f.write("*SOLID SECTION, ELSET=SOLID, MATERIAL=M\n")
        f.write("*RIGID BODY, NSET=PLATF, REF NODE=%d, ROT NODE=%d\n" % (ref, ref + 1))
        for k in range(6):
            f.write("*STEP\n*STATIC\n*BOUNDARY, OP=NEW\nCLAMP, 1, 3, 0.\n")
            for dof in range(6):
                f.write("%d, %d, %d, %.6g\n" % (ref + (0 if dof < 3 else 1), dof % 3 + 1, dof % 3 + 1,
                                                DELTA if dof == k else 0.0))
            f.write("*NODE PRINT, NSET=PLAT\nRF\n*END STEP\n")
    with open(os.path.join(workdir, "ccx.log"), "w") as log:
        subprocess.run(["ccx", "-i", "hr"], cwd=workdir, stdout=log, stderr=subprocess.STDOUT, check=True)
    k = read_reactions(os.path.join(workdir, "hr.dat"), ref)
    return 0.5 * (k + k.T)


def solve_pair(design, workdir, fine, step=""):
    p = design["parameters"]
    members = members_from_parameters(design)
    members = [(a, b, ya, w, za, h, 1, 0) for (a, b, ya, w, za, h, _, _) in members]  # rim bonded
    r_hub, r_rim = p["hub_radius_m"], p["rim_radius_m"]
    w, h = p["beam_width_m"], p["beam_height_m"]
    rim_w = max(w, h)
    coarse = 2 * fine
    near_beams = lambda x, y, z: r_hub - 0.5 * h < math.hypot(x, y) < r_rim + 0.5 * rim_w
    out = {}
    t0 = time.time()

    def members_only(occ):
        for (a, b, ya, ww, za, hh, _, _) in members:
            length = np.linalg.norm(b - a)
            tag = occ.addBox(0, -ww / 2, -hh / 2, length, ww, hh)
            m = np.eye(4)
            m[:3, :3] = np.column_stack([(b - a) / length, ya, za])
            m[:3, 3] = a
            occ.affineTransform([(3, tag)], list(m[:3, :].flatten()))

    nodes, tets = mesh_tets(members_only, fine, fine, near_beams)
    faces = end_face_bodies(nodes, members)
    print("  members only: %d nodes, %d C3D10; solving…" % (len(nodes), len(tets)), flush=True)
    out["members_only"] = write_and_solve(os.path.join(workdir, "members"), nodes, tets, design["material"],
                                          faces[1], faces[0])
    out["members_only_nodes"] = len(nodes)

    def as_drawn(occ):
        parts = [(3, occ.addCylinder(0, 0, -h / 2, 0, 0, h, r_hub))]
        for (a, b, ya, ww, za, hh, _, _) in members:
            x = (b - a) / np.linalg.norm(b - a)
            start = 0.5 * r_hub  # reaching into the hub and the rim, so that the solids fuse
            length = r_rim + 0.5 * rim_w - start
            tag = occ.addBox(0, -ww / 2, -hh / 2, length, ww, hh)
            m = np.eye(4)
            m[:3, :3] = np.column_stack([x, ya, za])
            m[:3, 3] = start * x
            occ.affineTransform([(3, tag)], list(m[:3, :].flatten()))
            parts.append((3, tag))
        outer = occ.addCylinder(0, 0, -h / 2, 0, 0, h, r_rim + rim_w)
        inner = occ.addCylinder(0, 0, -h / 2, 0, 0, h, r_rim)
        ring, _ = occ.cut([(3, outer)], [(3, inner)])
        occ.fuse(parts[:1], parts[1:] + ring)

    def exported(occ):  # the body `ftsim design --step` wrote (millimetres), in metres
        occ.importShapes(step)
        occ.dilate(occ.getEntities(3), 0, 0, 0, 1e-3, 1e-3, 1e-3)

    nodes, tets = mesh_tets(exported if step else as_drawn, fine, coarse, near_beams, straight=bool(step))
    platform = [n for n, q in nodes.items() if abs(q[2] - h / 2) < 1e-9 and math.hypot(q[0], q[1]) <= r_hub + 1e-9]
    clamped = [n for n, q in nodes.items() if abs(q[2] + h / 2) < 1e-9 and math.hypot(q[0], q[1]) >= r_rim - 1e-9]
    print("  hub and rim elastic: %d nodes, %d C3D10, flange %d nodes, mount %d nodes; solving…"
          % (len(nodes), len(tets), len(platform), len(clamped)), flush=True)
    out["as_drawn"] = write_and_solve(os.path.join(workdir, "drawn"), nodes, tets, design["material"],
                                      platform, clamped)
    out["as_drawn_nodes"] = len(nodes)
    out["seconds"] = time.time() - t0
    out["element_size_m"] = fine
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("design")
    ap.add_argument("workdir")
    ap.add_argument("--size-m", type=float, default=0.0)
    ap.add_argument("--refine", type=float, default=1.5)
    ap.add_argument("--out", default="")
    ap.add_argument("--step", default="", help="mesh this STEP file (ftsim design --step) as the body as drawn")
    a = ap.parse_args()
    design = json.load(open(a.design))
    if design["family"] != "hub-spoke":
        raise SystemExit("only the hub-spoke family has a hub and a rim to draw")
    p = design["parameters"]
    size = a.size_m or min(p["beam_width_m"], p["beam_height_m"]) / 3
    runs = [solve_pair(design, os.path.join(a.workdir, "m1"), size, a.step),
            solve_pair(design, os.path.join(a.workdir, "m2"), size / a.refine, a.step)]
    model = np.array(design["stiffness_si"])
    rows = []
    print("%-6s %12s %12s %12s %10s %10s %10s" % ("term", "model", "members FE", "as drawn FE", "drawn/memb",
                                                   "model/drawn", "mesh1/2"))
    for k in range(6):
        m_only, drawn = runs[-1]["members_only"][k, k], runs[-1]["as_drawn"][k, k]
        first = runs[0]["as_drawn"][k, k] / runs[0]["members_only"][k, k]
        row = {"term": "K" + AXES[k] + AXES[k], "model": model[k, k], "members_only": m_only, "as_drawn": drawn,
               "drawn_over_members": drawn / m_only, "model_over_drawn": model[k, k] / drawn,
               "drawn_over_members_mesh1": first}
        rows.append(row)
        print("%-6s %12.5g %12.5g %12.5g %10.4f %10.4f %10.4f" % (row["term"], model[k, k], m_only, drawn,
                                                                 drawn / m_only, model[k, k] / drawn,
                                                                 first / (drawn / m_only)))
    for r in runs:
        print("  mesh %.3g mm: members only %d nodes, as drawn %d nodes, %.1f s"
              % (1e3 * r["element_size_m"], r["members_only_nodes"], r["as_drawn_nodes"], r["seconds"]))
    if a.out:
        json.dump({"rows": rows, "meshes": [{k: r[k] for k in ("element_size_m", "members_only_nodes",
                                                              "as_drawn_nodes", "seconds")} for r in runs]},
                  open(a.out, "w"), indent=1)


if __name__ == "__main__":
    main()
