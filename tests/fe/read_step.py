#!/usr/bin/python3
"""Opens a STEP file in gmsh (Debian's python3-gmsh, a separate process from ftsim) and reports
what a CAD user would see: the solids and their volume, and for each query point the surface
face it lies on.

usage: read_step.py BODY.step POINTS.json OUT.json
POINTS.json: [{"point_mm": [x, y, z], "normal": [nx, ny, nz]}, ...]. For each point OUT.json gives
the distance to the nearest face whose surface passes through the point with the point inside
the face's trimmed boundary (so "on the solid's surface", not on an untrimmed plane; null when
there is none), whether that face's normal is parallel
to the given one, and the distance from the point to the centre of mass of the smallest face
containing it (an imprinted gauge pad is centred on its site).
"""
import json
import sys

import gmsh


def main():
    step, points_path, out_path = sys.argv[1:4]
    points = json.load(open(points_path))
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.occ.importShapes(step)
    gmsh.model.occ.synchronize()
    volumes = gmsh.model.getEntities(3)
    faces = [tag for _, tag in gmsh.model.getEntities(2)]
    out = {"solids": len(volumes),
           "volume_mm3": sum(gmsh.model.occ.getMass(3, tag) for _, tag in volumes),
           "faces": len(faces), "points": []}
    for p in points:
        best = {"surface_distance_mm": None, "normal_parallel": False,
                "pad_centre_distance_mm": None, "pad_area_mm2": 0.0}
        smallest_area = float("inf")
        for tag in faces:
            box = gmsh.model.getBoundingBox(2, tag)
            if any(not box[k] - 1e-3 <= p["point_mm"][k] <= box[k + 3] + 1e-3 for k in range(3)):
                continue
            try:  # the point's (u, v) on this face's surface; fails far from it
                uv = list(gmsh.model.getParametrization(2, tag, p["point_mm"]))
            except Exception:
                continue
            on = gmsh.model.getValue(2, tag, uv)
            dist = float(sum((a - b) ** 2 for a, b in zip(on, p["point_mm"])) ** 0.5)
            if dist > 1e-4 or gmsh.model.isInside(2, tag, uv) < 1:  # off it, or outside its trim
                continue
            normal = gmsh.model.getNormal(tag, uv)
            parallel = bool(abs(sum(a * b for a, b in zip(normal, p["normal"]))) > 0.999)
            best["surface_distance_mm"] = min(best["surface_distance_mm"] or dist, dist)
            best["normal_parallel"] = best["normal_parallel"] or parallel
            area = gmsh.model.occ.getMass(2, tag)
            if area < smallest_area:
                smallest_area = area
                centre = gmsh.model.occ.getCenterOfMass(2, tag)
                best["pad_centre_distance_mm"] = float(sum((a - b) ** 2 for a, b in zip(centre, p["point_mm"])) ** 0.5)
                best["pad_area_mm2"] = float(area)
        out["points"].append(best)
    gmsh.finalize()
    json.dump(out, open(out_path, "w"), indent=1)


if __name__ == "__main__":
    main()
