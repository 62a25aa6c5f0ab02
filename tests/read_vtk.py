"""Read weft-vtk's time series with VTK's own XML reader (the one ParaView uses) and check
it against the model and run tables read with pandas: cell counts and types, cell
connectivity, times, points, displacements, velocities, nodal thickness, projectile.

usage: python3 read_vtk.py MODEL_DIR RUN_DIR VTK_DIR
Prints the measured differences; exits non-zero on the first failed check.
"""
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pandas as pd
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

model, run, out = Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3])
VTK_TYPE = {"truss": 3, "link": 3, "beam": 3, "tri": 5, "quad": 9, "point_mass": 1}
NPE = {"truss": 2, "link": 2, "beam": 2, "tri": 3, "quad": 4, "point_mass": 1}


def check(ok, what):
    if not ok:
        print(f"FAIL: {what}")
        sys.exit(1)


nodes = pd.read_parquet(model / "nodes.parquet")
hist = pd.read_parquet(run / "history.parquet")
elements = {}
for k in VTK_TYPE:
    p = model / f"elements_{k}.parquet"
    if p.exists():
        elements[k] = pd.read_parquet(p)
expected_types = {}
for k, e in elements.items():
    expected_types[VTK_TYPE[k]] = expected_types.get(VTK_TYPE[k], 0) + len(e)
n_cells = sum(len(e) for e in elements.values())

# The collection: one mesh per history time, with its exact time.
root = ET.parse(out / "weft.pvd").getroot()
check(root.get("type") == "Collection", "weft.pvd is a VTK Collection")
sets = root.find("Collection").findall("DataSet")
mesh = [d for d in sets if d.get("part") == "0"]
times = np.array(sorted(hist["t"].unique()))
got = np.array([float(d.get("timestep")) for d in mesh])
check(len(got) == len(times) and np.array_equal(got, times), f"pvd times {got} vs history {times}")
print(f"pvd: {len(mesh)} mesh files, times equal to the history's ({times[0]:g} .. {times[-1]:g} s)")
prov = (out / "weft.pvd").read_text().split("weft.provenance: ", 1)
check(len(prov) == 2 and '"stage":"vtk"' in prov[1], "provenance comment in weft.pvd")


def read(path):
    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    check(r.GetErrorCode() == 0, f"VTK reads {path}")
    return r.GetOutput()


x0 = nodes[["x", "y", "z"]].to_numpy()
if "ux0" in nodes:
    x0 = x0 + nodes[["ux0", "uy0", "uz0"]].fillna(0.0).to_numpy()
worst = {"displacement": 0.0, "velocity": 0.0, "points": 0.0}
for k in sorted({0, len(mesh) // 2, len(mesh) - 1}):
    g = read(out / mesh[k].get("file"))
    t = times[k]
    check(g.GetNumberOfPoints() == len(nodes), f"points {g.GetNumberOfPoints()} vs {len(nodes)} nodes")
    check(g.GetNumberOfCells() == n_cells, f"cells {g.GetNumberOfCells()} vs {n_cells} elements")
    types = vtk_to_numpy(g.GetCellTypesArray()) if hasattr(g, "GetCellTypesArray") else \
        np.array([g.GetCellType(i) for i in range(g.GetNumberOfCells())])
    counts = {int(ty): int((types == ty).sum()) for ty in np.unique(types)}
    check(counts == expected_types, f"cell types {counts} vs {expected_types}")
    pd_ = g.GetPointData()
    node_id = vtk_to_numpy(pd_.GetArray("node_id"))
    check(np.array_equal(node_id, nodes["node_id"].to_numpy()), "node_id point data in nodes.parquet order")
    h = hist[hist["t"] == t].set_index("node_id").loc[node_id]
    for name, cols in [("displacement", ["ux", "uy", "uz"]), ("velocity", ["vx", "vy", "vz"])]:
        a = vtk_to_numpy(pd_.GetArray(name))
        d = np.abs(a - h[cols].to_numpy()).max()
        worst[name] = max(worst[name], d)
        check(d == 0.0, f"{name} at t = {t}: max difference {d}")
    pts = vtk_to_numpy(g.GetPoints().GetData())
    d = np.abs(pts - (x0 + h[["ux", "uy", "uz"]].to_numpy())).max()
    worst["points"] = max(worst["points"], d)
    check(d <= 1e-15 * max(1.0, np.abs(x0).max()), f"points = X + u0 + u at t = {t}: {d}")
    # Every cell joins its element's nodes, with its id, part and kind.
    cd = g.GetCellData()
    eid = vtk_to_numpy(cd.GetArray("element_id"))
    pid = vtk_to_numpy(cd.GetArray("part_id"))
    for kind, e in elements.items():
        e = e.set_index("element_id")
        cols = ["n1", "n2", "n3", "n4"][: NPE[kind]]
        for c in np.nonzero(np.isin(eid, e.index.to_numpy()))[0]:
            ids = g.GetCell(int(c)).GetPointIds()
            got_nodes = [int(node_id[ids.GetId(j)]) for j in range(ids.GetNumberOfIds())]
            row = e.loc[eid[c]]
            check(got_nodes == [int(row[n]) for n in cols], f"cell {c} (element {eid[c]}) nodes {got_nodes}")
            check(pid[c] == row["part_id"], f"cell {c} part")
            check(types[c] == VTK_TYPE[kind], f"cell {c} type")
# Element results: each column of elements.parquet is cell data with the same values.
if (run / "elements.parquet").exists():
    er = pd.read_parquet(run / "elements.parquet")
    quantities = [c for c in er.columns if c not in ("t", "element_id", "part_id", "kind")]
    k = len(mesh) - 1
    g = read(out / mesh[k].get("file"))
    cd = g.GetCellData()
    eid = vtk_to_numpy(cd.GetArray("element_id"))
    rows = er[er["t"] == times[k]].set_index("element_id")
    for c in quantities:
        a = vtk_to_numpy(cd.GetArray(c))
        want = rows[c].reindex(eid).to_numpy(dtype=float)  # no row (point mass): NaN
        same = (a == want) | (np.isnan(a) & np.isnan(want))
        check(same.all(), f"cell data {c} vs elements.parquet")
    print(f"element results: {len(quantities)} columns as cell data, equal to elements.parquet at t = {times[k]:g} s "
          f"({int(rows['axial_force'].notna().sum())} axial forces, {int(rows['stress_11'].notna().sum())} membrane stresses)")
print(f"cells: {n_cells} with types {expected_types}, connectivity, element and part ids as in the element tables")
print("max |difference| against history.parquet: " + ", ".join(f"{k} {v:.1e}" for k, v in worst.items()))

# Nodal thickness: the mean over the membrane elements at the node of their thickness there.
g = read(out / mesh[0].get("file"))
th = g.GetPointData().GetArray("thickness")
parts = pd.read_parquet(model / "parts.parquet").set_index("part_id")
mem = [k for k in ("tri", "quad") if k in elements]
if mem:
    check(th is not None, "thickness point data for a model with membranes")
    th = vtk_to_numpy(th)
    acc = {}
    for kind in mem:
        e = elements[kind]
        for j in range(NPE[kind]):
            tcol = f"t{j + 1}"
            tv = e[tcol] if tcol in e else pd.Series(np.nan, index=e.index)
            tv = tv.fillna(e["part_id"].map(parts["thickness"]))
            for n, v in zip(e[f"n{j + 1}"], tv):
                acc.setdefault(n, []).append(v)
    pos = {n: i for i, n in enumerate(nodes["node_id"])}
    d = max(abs(th[pos[n]] - np.mean(v)) for n, v in acc.items())
    check(d <= 1e-18, f"nodal thickness: max difference {d}")
    print(f"thickness: {len(acc)} membrane nodes, max difference {d:.1e} m (values {th.min():.3g} .. {th.max():.3g} m)")

# The projectile's surface: its tip where projectile.parquet puts it, radius R.
proj = [d for d in sets if d.get("part") == "1"]
if (model / "projectile.parquet").exists():
    spec = pd.read_parquet(model / "projectile.parquet").iloc[0]
    res = pd.read_parquet(run / "projectile.parquet")
    check(len(proj) == len(mesh), "one projectile surface per time")
    g = read(out / proj[-1].get("file"))
    pts = vtk_to_numpy(g.GetPoints().GetData())
    row = res[res["t"] == times[-1]].iloc[0]
    tip = np.array([row["x"], row["y"], row["z"]])
    axis = np.array([spec.get("axis_x", 0.0), spec.get("axis_y", 0.0), spec.get("axis_z", -1.0)], dtype=float)
    axis = np.nan_to_num(axis, nan=0.0)
    if not axis.any():
        axis = np.array([0.0, 0.0, -1.0])
    axis /= np.linalg.norm(axis)
    s = (tip - pts) @ axis  # distance back from the tip along the axis
    radial = np.linalg.norm((pts - tip) + np.outer(s, axis), axis=1)
    check(abs(s.min()) <= 1e-15 and radial.max() <= spec["radius"] * (1 + 1e-12),
          f"projectile tip {s.min()}, radius {radial.max()} vs {spec['radius']}")
    print(f"projectile: {g.GetNumberOfCells()} faces, tip at {tip}, largest radius {radial.max():.6e} m (R = {spec['radius']:.6e})")
print("OK")
