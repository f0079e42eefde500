#!/usr/bin/python3
"""Independent solid FE solution of a design for checking `ftsim design` (beam model and --fe-check).

Written separately from the tool's deck writer (sim/design/fe_deck.cpp): the body is rebuilt from
the design's family parameters (not from the tool's member list) with gmsh's OpenCASCADE kernel
through its Python API, meshed with structured 20-node hexahedra, solved by CalculiX with
reduced-integration C3D20R elements under *unit displacements* of the platform (stiffness from the
reaction forces, not from compliance under unit loads), and the gauge strains are the slope of a
quadratic fit of the surface displacement along each grid (not nodal strain tensors).

usage: independent_fe.py DESIGN.json WORKDIR [--size-m S] [--refine R] [--out RESULT.json]
DESIGN.json is what `ftsim design --eval … --json` writes (family, parameters, material, gauge
grids, the model's figures and optionally its own fe_check).
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time

import gmsh
import numpy as np

AXES = ["Fx", "Fy", "Fz", "Mx", "My", "Mz"]
DELTA = 1e-6  # imposed platform displacement (m) or rotation (rad) per step


def members_from_parameters(design):
    """(start, end, width_axis, width, height_axis, height, body_start, body_end) per member.

    Bodies: 0 ground, 1 platform, 2 and 3 the guided family's intermediate stages."""
    p = design["parameters"]
    fam = design["family"]
    out = []
    if fam == "hub-spoke":
        n = int(round(p["beams"]))
        # a floating (radially released) rim joint: each beam's rim end on a body of its own
        floating = p.get("rim_compliance_radial_m_per_n", 0.0) > 0
        for i in range(n):
            th = 2 * math.pi * i / n
            x = np.array([math.cos(th), math.sin(th), 0.0])
            y = np.array([-math.sin(th), math.cos(th), 0.0])
            out.append((p["hub_radius_m"] * x, p["rim_radius_m"] * x, y, p["beam_width_m"],
                        np.array([0.0, 0.0, 1.0]), p["beam_height_m"], 1, 2 + i if floating else 0))
        return out
    if fam != "guided":
        raise SystemExit("unknown family " + fam)
    e = np.eye(3)
    # stage: compliant axis c, leaf axis l, inner body, outer body, thickness
    stages = [(e[2], e[0], 1, 2, p["leaf_thickness_z_m"]),
              (e[0], e[1], 2, 3, p["leaf_thickness_m"]),
              (e[1], e[2], 3, 0, p["leaf_thickness_m"])]
    gap = p.get("gap_m", 0.01)
    length, sep = p["leaf_length_m"], p["separation_m"]
    for st, (c, l, inner_body, outer_body, t) in enumerate(stages):
        w_axis = np.cross(c, l)
        r_in = p["inner_radius_m"] + st * (length + gap)
        for side in (1.0, -1.0):
            for leaf in (1.0, -1.0):
                inner = side * r_in * l + leaf * 0.5 * sep * c
                outer = inner + side * length * l
                out.append((outer, inner, w_axis, p["leaf_width_m"], c, t, outer_body, inner_body))
    return out


def build_mesh(members, size, layers):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("body")
    occ = gmsh.model.occ
    for (a, b, ya, w, za, h, _, _) in members:
        x = (b - a) / np.linalg.norm(b - a)
        length = np.linalg.norm(b - a)
        tag = occ.addBox(0, -w / 2, -h / 2, length, w, h)
        # local (x, y, z) -> global: the columns of R are the member's axes
        rot = np.column_stack([x, ya, za])
        m = np.eye(4)
        m[:3, :3] = rot
        m[:3, 3] = a
        occ.affineTransform([(3, tag)], list(m[:3, :].flatten()))
    occ.synchronize()
    lengths = [np.linalg.norm(m[1] - m[0]) for m in members]
    for (dim, tag) in gmsh.model.getEntities(1):
        xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(dim, tag)
        span = math.sqrt((xmax - xmin) ** 2 + (ymax - ymin) ** 2 + (zmax - zmin) ** 2)
        # along a member: `size`; across its section: twice as coarse (fields vary slowly there)
        along = any(abs(span - length) < 1e-3 * length for length in lengths)
        n = int(math.ceil(span / (size if along else 2 * size) - 1e-9))
        gmsh.model.mesh.setTransfiniteCurve(tag, max(layers, n) + 1)
    for (dim, tag) in gmsh.model.getEntities(2):
        gmsh.model.mesh.setTransfiniteSurface(tag)
        gmsh.model.mesh.setRecombine(2, tag)
    for (dim, tag) in gmsh.model.getEntities(3):
        gmsh.model.mesh.setTransfiniteVolume(tag)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    nodes = dict(zip((int(t) for t in tags), coords.reshape(-1, 3)))
    types, _, conn = gmsh.model.mesh.getElements(3)
    hexes = []
    for ty, cn in zip(types, conn):
        name, _, _, nn, _, _ = gmsh.model.mesh.getElementProperties(ty)
        if nn != 20:
            raise SystemExit("expected 20-node hexahedra, got " + name)
        hexes += [list(map(int, cn[i:i + 20])) for i in range(0, len(cn), 20)]
    gmsh.finalize()
    return nodes, hexes


# gmsh's 20-node hexahedron numbers its mid-edge nodes by edges (0,1),(0,3),(0,4),(1,2),(1,5),
# (2,3),(2,6),(3,7),(4,5),(4,7),(5,6),(6,7); CalculiX's C3D20 by (1,2),(2,3),(3,4),(4,1),(5,6),
# (6,7),(7,8),(8,5),(1,5),(2,6),(3,7),(4,8).
GMSH_TO_CCX = [0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15]


def end_face_bodies(nodes, members):
    body_nodes = {}
    for nid, p in nodes.items():
        for (a, b, ya, w, za, h, ba, bb) in members:
            length = np.linalg.norm(b - a)
            x = (b - a) / length
            r = p - a
            if abs(r @ ya) > w / 2 * (1 + 1e-6) or abs(r @ za) > h / 2 * (1 + 1e-6):
                continue
            s = r @ x
            if abs(s) < 1e-7 * length:
                body_nodes.setdefault(ba, []).append(nid)
            elif abs(s - length) < 1e-7 * length:
                body_nodes.setdefault(bb, []).append(nid)
    return body_nodes


def write_deck(path, nodes, hexes, bodies, material, n_bodies, members, radial_compliance):
    """Bodies 2… of a hub-spoke design are floating rim joints: rotation held, tangential and
    axial translation held by equations, radial translation on a spring of 1/compliance."""
    top = max(nodes)
    ref = {b: top + 100 + 4 * b for b in range(1, n_bodies)}
    # only a hub-spoke body with a rim compliance has floating joints (a guided body's bodies 2 and 3
    # are its rigid intermediate stages)
    radial = {m[7]: (m[1] - m[0]) / np.linalg.norm(m[1] - m[0])
              for m in members if m[7] >= 2 and radial_compliance > 0}
    with open(path, "w") as f:
        f.write("** independent FE check (tests/fe/independent_fe.py), SI units\n*NODE\n")
        for nid, p in nodes.items():
            # CalculiX reads at most 20 characters per field: 12 digits, round-off zeroed
            q = [0.0 if abs(v) < 1e-15 else v for v in p]
            f.write("%d, %.12g, %.12g, %.12g\n" % (nid, q[0], q[1], q[2]))
        for b in ref.values():
            f.write("%d, 0, 0, 0\n%d, 0, 0, 0\n" % (b, b + 1))
        for b, r in radial.items():  # spring anchor, 20 mm out along the beam
            f.write("%d, %.12g, %.12g, %.12g\n" % (ref[b] + 2, *(0.02 * r)))
        f.write("*ELEMENT, TYPE=C3D20R, ELSET=SOLID\n")
        for i, h in enumerate(hexes):
            ids = [h[k] for k in GMSH_TO_CCX]
            c = [nodes[n] for n in ids[:4]] + [nodes[ids[4]]]
            if np.cross(c[1] - c[0], c[3] - c[0]) @ (c[4] - c[0]) < 0:  # left-handed: swap faces
                ids = ids[4:8] + ids[0:4] + ids[12:16] + ids[8:12] + ids[16:20]
            f.write("%d, %s,\n%s\n" % (i + 1, ", ".join(map(str, ids[:15])),
                                        ", ".join(map(str, ids[15:]))))
        for b, ids in bodies.items():
            f.write("*NSET, NSET=FACE%d\n" % b)
            for k in range(0, len(ids), 12):
                f.write(", ".join(map(str, ids[k:k + 12])) + ",\n")
        f.write("*NSET, NSET=PLAT\n%d, %d\n" % (ref[1], ref[1] + 1))
        f.write("*MATERIAL, NAME=M\n*ELASTIC\n%.10g, %.6g\n" % (material["e_pa"], material["poisson"]))
        f.write("*SOLID SECTION, ELSET=SOLID, MATERIAL=M\n")
        for b, r in ref.items():
            f.write("*RIGID BODY, NSET=FACE%d, REF NODE=%d, ROT NODE=%d\n" % (b, r, r + 1))
        for b, r in radial.items():
            t = np.array([-r[1], r[0], 0.0])  # tangential, in the sensor plane
            f.write("*EQUATION\n1\n%d, 3, 1.\n" % ref[b])
            lead = 1 if abs(t[0]) >= abs(t[1]) else 2
            other = 3 - lead
            if abs(t[other - 1]) > 1e-12:
                f.write("*EQUATION\n2\n%d, %d, %.12g, %d, %d, %.12g\n"
                        % (ref[b], lead, t[lead - 1], ref[b], other, t[other - 1]))
            else:
                f.write("*EQUATION\n1\n%d, %d, 1.\n" % (ref[b], lead))
            f.write("*ELEMENT, TYPE=SPRINGA, ELSET=SPR%d\n%d, %d, %d\n*SPRING, ELSET=SPR%d\n\n%.10e\n"
                    % (b, len(hexes) + b, ref[b], ref[b] + 2, b, 1.0 / radial_compliance))
        for k in range(6):
            f.write("*STEP\n*STATIC\n*BOUNDARY, OP=NEW\n")
            if 0 in bodies:
                f.write("FACE0, 1, 3, 0.\n")
            for b in radial:
                f.write("%d, 1, 3, 0.\n%d, 1, 3, 0.\n" % (ref[b] + 1, ref[b] + 2))
            for dof in range(6):
                node = ref[1] + (0 if dof < 3 else 1)
                f.write("%d, %d, %d, %.6g\n" % (node, dof % 3 + 1, dof % 3 + 1,
                                                DELTA if dof == k else 0.0))
            f.write("*NODE PRINT, NSET=PLAT\nRF\n*NODE FILE\nU\n*END STEP\n")
    return ref


def read_reactions(path, ref_node):
    k = np.full((6, 6), np.nan)
    step = -1
    with open(path) as f:
        for line in f:
            if "forces (fx,fy,fz) for set PLAT" in line:
                step += 1
                continue
            parts = line.split()
            if step < 0 or len(parts) != 4:
                continue
            try:
                nid, vals = int(parts[0]), [float(v) for v in parts[1:]]
            except ValueError:
                continue
            if nid in (ref_node, ref_node + 1):
                row = 0 if nid == ref_node else 3
                k[row:row + 3, step] = np.array(vals) / DELTA
    if np.isnan(k).any():
        raise SystemExit("reactions missing in " + path)
    return k


def read_displacements(path):
    steps, cur = [], None
    with open(path) as f:
        for line in f:
            if line.startswith(" -4"):
                cur = {} if line.split()[1] == "DISP" else None
                if cur is not None:
                    steps.append(cur)
            elif line.startswith(" -3"):
                cur = None
            elif cur is not None and line.startswith(" -1"):
                cur[int(line[3:13])] = np.array([float(line[13 + 12 * i:25 + 12 * i]) for i in range(3)])
    return steps


def gauge_slopes(nodes, disp_steps, gauges, members):
    """Strain along each grid per unit platform displacement (G × 6): the derivative at the grid
    centre of a quadratic fit u·d = a + b·s + c·s² + e·q + f·s·q over surface nodes near it."""
    ids = np.array(list(nodes.keys()))
    xyz = np.array([nodes[i] for i in ids])
    out = np.zeros((len(gauges), 6))
    for g, gauge in enumerate(gauges):
        p0, d, n = (np.array(gauge[k]) for k in ("point_m", "direction", "normal"))
        q_axis = np.cross(n, d)
        # the member the grid lies on and the distance to its nearer end
        best = None
        for (a, b, ya, w, za, h, _, _) in members:
            length = np.linalg.norm(b - a)
            x = (b - a) / length
            s = (p0 - a) @ x
            off = np.linalg.norm((p0 - a) - s * x)
            face = abs(q_axis @ ya) * w + abs(q_axis @ za) * h
            if -1e-9 <= s <= length + 1e-9 and (best is None or off < best[0]):
                best = (off, min(s, length - s), length, face, min(w, h))
        # along: up to 20 % of the member, keeping a quarter section depth off the clamped end
        half = min(0.2 * best[2], best[1] - 0.25 * best[4])
        r = xyz - p0
        s = r @ d
        q = r @ q_axis
        sel = (np.abs(r @ n) < 1e-7) & (np.abs(s) <= half) & (np.abs(q) <= 0.3 * best[3] + 1e-9)
        if len(np.unique(np.round(s[sel], 9))) < 3:
            raise SystemExit("gauge %d (%s): fewer than 3 node rows under it; refine" % (g, gauge["name"]))
        a_mat = np.column_stack([np.ones(sel.sum()), s[sel], s[sel] ** 2, q[sel], s[sel] * q[sel], q[sel] ** 2])
        for k in range(6):
            u = np.array([disp_steps[k][i] for i in ids[sel]]) @ d
            coef, *_ = np.linalg.lstsq(a_mat, u, rcond=None)
            out[g, k] = coef[1] / DELTA
    return out


def solve(design, members, workdir, size, layers):
    os.makedirs(workdir, exist_ok=True)
    t0 = time.time()
    nodes, hexes = build_mesh(members, size, layers)
    bodies = end_face_bodies(nodes, members)
    n_bodies = 1 + max(max(m[6], m[7]) for m in members)
    ref = write_deck(os.path.join(workdir, "ind.inp"), nodes, hexes, bodies, design["material"], n_bodies,
                     members, design["parameters"].get("rim_compliance_radial_m_per_n", 0.0))
    print("  mesh %.3g mm, %d layers: %d nodes, %d C3D20R; solving…" % (1e3 * size, layers, len(nodes), len(hexes)),
          flush=True)
    with open(os.path.join(workdir, "ccx.log"), "w") as log:
        subprocess.run(["ccx", "-i", "ind"], cwd=workdir, stdout=log, stderr=subprocess.STDOUT, check=True)
    k = read_reactions(os.path.join(workdir, "ind.dat"), ref[1])
    k = 0.5 * (k + k.T)
    c = np.linalg.inv(k)
    disp = read_displacements(os.path.join(workdir, "ind.frd"))
    strain_per_disp = gauge_slopes(nodes, disp, design["gauges"], members)
    return {"element_size_m": size, "layers": layers, "nodes": len(nodes), "seconds": time.time() - t0,
            "stiffness": k, "gauge_strain": strain_per_disp @ c}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("design")
    ap.add_argument("workdir")
    ap.add_argument("--size-m", type=float, default=0.0)
    ap.add_argument("--refine", type=float, default=1.5)
    ap.add_argument("--out", default="")
    a = ap.parse_args()
    design = json.load(open(a.design))
    members = members_from_parameters(design)
    size = a.size_m or min(np.linalg.norm(m[1] - m[0]) for m in members) / 12
    sols = [solve(design, members, os.path.join(a.workdir, "ind1"), size, 2),
            solve(design, members, os.path.join(a.workdir, "ind2"), size / a.refine, 3)]
    fe, first = sols[-1], sols[0]
    model_k = np.array(design["stiffness_si"])
    model_g = np.array([g["strain_per_unit_wrench"] for g in design["gauges"]])
    tool = design.get("fe_check", {}).get("meshes", [])
    tool_k = np.array(tool[-1]["stiffness_diagonal_si"]) if tool else None
    tool_g = {(d["gauge"], d["axis"]): d["strain"] for d in tool[-1]["dominant_strain_per_unit_wrench"]} if tool else {}
    rows = []
    print("%-28s %12s %12s %12s %9s %9s %9s" % ("figure", "model", "independent", "tool FE",
                                                  "model/ind", "tool/ind", "m1/m2"))
    for k in range(6):
        tk = tool_k[k] if tool_k is not None else float("nan")
        rows.append({"figure": "K" + AXES[k] + AXES[k], "model": model_k[k, k], "independent": fe["stiffness"][k, k],
                     "tool_fe": tk, "mesh_change": first["stiffness"][k, k] / fe["stiffness"][k, k]})
    top = np.abs(model_g).max(axis=0)
    for g in range(model_g.shape[0]):
        for k in range(6):
            if top[k] > 0 and abs(model_g[g, k]) >= 0.25 * top[k]:
                rows.append({"figure": "gauge %d %s" % (g, AXES[k]), "model": model_g[g, k],
                             "independent": fe["gauge_strain"][g, k], "tool_fe": tool_g.get((g, AXES[k]), float("nan")),
                             "mesh_change": first["gauge_strain"][g, k] / fe["gauge_strain"][g, k]})
    for r in rows:
        r["model_ratio"] = r["model"] / r["independent"]
        r["tool_ratio"] = r["tool_fe"] / r["independent"]
        print("%-28s %12.5g %12.5g %12.5g %9.4f %9.4f %9.4f" % (r["figure"], r["model"], r["independent"], r["tool_fe"],
                                                               r["model_ratio"], r["tool_ratio"], r["mesh_change"]))
    worst_model = max(abs(r["model_ratio"] - 1) for r in rows)
    tool_dev = [abs(r["tool_ratio"] - 1) for r in rows if not math.isnan(r["tool_ratio"])]
    worst_tool = max(tool_dev) if tool_dev else float("nan")
    print("largest |model/independent - 1| = %.4f; largest |tool FE/independent - 1| = %.4f" % (worst_model, worst_tool))
    for s in sols:
        print("  mesh %.3g mm: %d nodes, %.1f s" % (1e3 * s["element_size_m"], s["nodes"], s["seconds"]))
    if a.out:
        json.dump({"rows": rows, "worst_model": worst_model, "worst_tool": worst_tool,
                   "meshes": [{"element_size_m": s["element_size_m"], "nodes": s["nodes"], "seconds": s["seconds"]}
                              for s in sols]}, open(a.out, "w"), indent=1)


if __name__ == "__main__":
    main()
