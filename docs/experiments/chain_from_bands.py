"""A measurement prototype, not a weft feature: the truss-chain version of a woven band
model ("a beam chain with a contact radius", issue 11's second representation), derived
from the band model's tables so that both run the same impact.

Each band becomes the chain of its centre-line nodes (the nodes of largest nodal
thickness), joined by trusses of the band's own section A = t_c w/2 (its nodal
thicknesses 0, t_c, 0 across the width w, t_c chosen by the generator so that A is the
lenticular area, ≈ (2/3) w h; half of it for the yarns on a symmetry plane, which carry
half a yarn); the yarns' contact keeps t_c as the contact thickness of the chain's nodes
and segments,
so that the unformed crossings (centre lines t_c apart) just touch, as the bands do.
Nodes, node sets, constraints, symmetry planes, projectile and analysis are the band
model's, restricted to the chain's nodes. The projectile meets the chains' nodes only
(no faces).

    ./target/release/weft-weave woven --out runs/w60
    python3 docs/experiments/chain_from_bands.py runs/w60 runs/c60 --time-step 2.632e-8
    ./target/release/weft-simulate --model runs/c60 --out runs/c60-impact --threads 2

`--time-step` fixes the step (the band model's, for a like-for-like run): the chain needs
four contact definitions (full and half yarns are separate truss parts), and the step
guard, which adds every definition a node takes part in, would otherwise take a 9 %
smaller step than the bands'.
"""
import argparse
import os
import shutil

import numpy as np
import pandas as pd

ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
ap.add_argument("bands", help="a woven band model folder (weft-weave woven)")
ap.add_argument("out", help="the chain model folder to write (replaced)")
ap.add_argument("--time-step", type=float, default=None, help="fixed time step [s]")
a = ap.parse_args()

read = lambda f: pd.read_parquet(os.path.join(a.bands, f + ".parquet"))
for f in ("nodes", "parts", "elements_quad", "contacts", "analysis", "symmetry", "projectile",
          "constraints", "node_sets"):
    if not os.path.exists(os.path.join(a.bands, f + ".parquet")):
        raise SystemExit(f"{a.bands}: no {f}.parquet; expected a woven band model "
                         "(weft-weave woven --out DIR)")
if os.path.abspath(a.out) == os.path.abspath(a.bands):
    raise SystemExit(f"{a.out}: the output folder is the input model; give another folder")
nodes, parts, quads = read("nodes"), read("parts"), read("elements_quad")
# Nodal thickness (largest over a node's quads) and family (its quads' part).
thick, fam = {}, {}
for k in range(1, 5):
    for n, t, p in zip(quads[f"n{k}"].values, quads[f"t{k}"].values, quads.part_id.values):
        thick[n] = max(thick.get(n, 0.0), t)
        fam[n] = p
t_c = max(thick.values())
# The width: a warp quad spans half of it across (y), the generator's two quads across.
xyz = nodes.set_index("node_id")
warp = quads[quads.part_id.map(dict(zip(parts.part_id, parts.name))).str.startswith("warp")]
ys = np.stack([xyz.loc[warp[f"n{k}"].values, "y"].values for k in range(1, 5)])
width = 2.0 * float(np.median(ys.max(axis=0) - ys.min(axis=0)))
area = 0.5 * t_c * width
centre = [n for n, t in thick.items() if t > 0.5 * t_c]
names = dict(zip(parts.part_id, parts.name))
trusses = []  # (part name, n1, n2)
for p in parts.part_id:
    fam_name = names[p].split("_")[0]  # warp or weft
    along, across = ("x", "y") if fam_name == "warp" else ("y", "x")
    pts = xyz.loc[[n for n in centre if fam[n] == p]]
    for c, yarn in pts.groupby(pts[across].round(9)):
        ids = yarn.sort_values(along).index.values
        part = f"{fam_name}_{'half' if abs(c) < 1e-9 else 'full'}"
        trusses += [(part, i, j) for i, j in zip(ids[:-1], ids[1:])]
keep = sorted({n for _, i, j in trusses for n in (i, j)})
part_names = sorted({t[0] for t in trusses})

shutil.rmtree(a.out, ignore_errors=True)
os.makedirs(a.out)
write = lambda df, f: df.to_parquet(os.path.join(a.out, f + ".parquet"), index=False)
rows = []
for i, name in enumerate(part_names):
    r = {c: None for c in parts.columns}
    r.update(part_id=i + 1, name=name, kind="truss", youngs_modulus=parts.youngs_modulus_1.iloc[0],
             density=parts.density.iloc[0], area=area / 2 if name.endswith("half") else area,
             tension_only=False, no_compression=False)
    rows.append(r)
P = pd.DataFrame(rows)
for c in parts.columns:
    if c not in ("tension_only", "no_compression"):
        P[c] = P[c].astype(parts[c].dtype)
write(P, "parts")
pid = {n: i + 1 for i, n in enumerate(part_names)}
write(pd.DataFrame({
    "element_id": np.arange(1, len(trusses) + 1, dtype=np.int64),
    "part_id": np.array([pid[t[0]] for t in trusses], dtype=np.int64),
    "n1": np.array([t[1] for t in trusses], dtype=np.int64),
    "n2": np.array([t[2] for t in trusses], dtype=np.int64),
}), "elements_truss")
write(nodes[nodes.node_id.isin(keep)], "nodes")
write(read("constraints").pipe(lambda d: d[d.node_id.isin(keep)]), "constraints")
sets = read("node_sets").pipe(lambda d: d[d.node_id.isin(keep)]).copy()
sets["order"] = sets.groupby("set").cumcount().astype(sets["order"].dtype)
write(sets, "node_sets")
analysis = read("analysis")
if a.time_step is not None:
    analysis["time_step"] = a.time_step
write(analysis, "analysis")
for f in ("symmetry", "projectile"):
    shutil.copy(os.path.join(a.bands, f + ".parquet"), os.path.join(a.out, f + ".parquet"))
c0 = read("contacts")
defs = []
for m in [n for n in part_names if n.startswith("warp")]:
    for s in [n for n in part_names if n.startswith("weft")]:
        r = c0.iloc[0].to_dict()
        r.update(contact_id=len(defs) + 1, master_part=m, slave_part=s,
                 slave_thickness=t_c, master_thickness=t_c)
        defs.append(r)
C = pd.DataFrame(defs)
for c in c0.columns:
    C[c] = C[c].astype(c0[c].dtype)
write(C, "contacts")
print(f"{a.out}: {len(keep)} nodes, {len(trusses)} trusses (w = {width:.4e} m, A = {area:.4e} m², "
      f"halved on the symmetry planes), contact thickness {t_c:.4e} m, {len(defs)} contact definitions")
