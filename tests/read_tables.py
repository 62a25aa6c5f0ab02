"""Open every weft table with pandas and polars, check the documented columns and
dtypes (docs/tables.md) and the provenance, then write model tables back with pandas
(snappy) and polars (zstd, large/view strings) and check that weft-simulate reads them.

usage: python3 read_tables.py WEFT_SIMULATE MODEL_DIR OUT_DIR SCRATCH_DIR [open-only]
(open-only: check the tables, skip the rod-specific write-back check)
"""
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import polars as pl
import pyarrow.parquet as pq

sim, model, out, scratch = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3]), Path(sys.argv[4])
open_only = len(sys.argv) > 5 and sys.argv[5] == "open-only"

EXPECT = {
    "nodes.parquet": {"node_id": "int64", "x": "float64", "y": "float64", "z": "float64"},
    "parts.parquet": {"part_id": "int64", "name": "string", "kind": "string", "youngs_modulus": "float64"},
    "elements_truss.parquet": {"element_id": "int64", "part_id": "int64", "n1": "int64", "n2": "int64"},
    "node_sets.parquet": {"set": "string", "node_id": "int64", "order": "int64"},
    "constraints.parquet": {"node_id": "int64", "fix_x": "bool", "fix_y": "bool", "fix_z": "bool"},
    "loads.parquet": {"load_id": "int64", "node_id": "int64", "fx": "float64", "law": "string", "start": "float64"},
    "analysis.parquet": {"end_time": "float64", "output_interval": "float64"},
    "history.parquet": {c: "float64" for c in ["t", "ux", "uy", "uz", "vx", "vy", "vz"]} | {"node_id": "int64"},
    "energy.parquet": {c: "float64" for c in ["t", "kinetic", "internal", "damping", "friction", "hourglass",
                                               "contact", "external_work", "balance_error", "balance_error_relative",
                                               "energy_scale"]},
    "summary.parquet": {"steps": "int64", "dt": "float64", "controlling_kind": "string",
                        "controlling_element": "int64", "added_mass": "float64", "threads": "int64",
                        "wall_time_contact": "float64", "contact_builds": "int64", "initial_penetrations": "int64"},
    "elements_quad.parquet": {c: "int64" for c in ["element_id", "part_id", "n1", "n2", "n3", "n4"]},
    "contacts.parquet": {"contact_id": "int64", "master_part": "string", "slave_part": "string",
                         "static_friction": "float64", "penalty_scale": "float64", "two_way": "bool",
                         "initial_penetration": "string"},
    "elements_tri.parquet": {c: "int64" for c in ["element_id", "part_id", "n1", "n2", "n3"]},
    "elements_beam.parquet": {c: "int64" for c in ["element_id", "part_id", "n1", "n2"]},
    "ties.parquet": {"slave": "int64", "m1": "int64", "m2": "int64"},
    "symmetry.parquet": {"normal": "string", "position": "float64"},
    "curves.parquet": {"curve": "string", "t": "float64", "value": "float64"},
    "fit_trace.parquet": {"evaluation": "int64", "start": "int64", "T": "float64", "best_T": "float64",
                          "wall_seconds": "float64", "membrane.G12": "float64"},
    "fit_result.parquet": {"name": "string", "value": "float64", "lower": "float64", "upper": "float64",
                           "T": "float64", "T_initial": "float64", "expected": "float64", "at_bound": "bool"},
    "error.parquet": {"node_id": "int64", "x": "float64", "peak_relative_error": "float64"},
    "error_summary.parquet": {"T": "float64", "max_peak_relative_error": "float64"},
    "failures.parquet": {"t": "float64", "step": "int64", "element_kind": "string", "element_id": "int64",
                         "part": "string", "layer": "int64", "yarn": "int64", "criterion": "string",
                         "value": "float64", "limit": "float64", "eroded": "bool"},
    "ballistic.parquet": {"t": "float64", "layer": "int64", "kinetic": "float64", "strain": "float64",
                          "eroded": "float64", "friction": "float64", "absorbed": "float64",
                          "deflection": "float64"},
    "form.parquet": {"steps": "int64", "kinetic_over_work": "float64", "max_residual_force": "float64",
                     "creep": "float64", "crimp_target": "float64", "warp_tension": "float64",
                     "warp_end_tension": "float64", "max_penetration_ratio": "float64"},
}
# Optional columns: checked when present.
OPTIONAL = {
    "nodes.parquet": {c: "float64" for c in ["ux0", "uy0", "uz0"]},
    "elements_quad.parquet": {c: "float64" for c in ["t1", "t2", "t3", "t4"]},
    "elements_tri.parquet": {c: "float64" for c in ["t1", "t2", "t3"]},
}
# Result tables that share a name with a model table.
RESULT_EXPECT = {
    "projectile.parquet": {"t": "float64", "projectile_id": "int64", "z": "float64", "vz": "float64", "fz": "float64"},
}

checked = 0
for folder in (model, out):
    for path in sorted(folder.glob("*.parquet")):
        df = pd.read_parquet(path)
        pf = pl.read_parquet(path)
        assert df.shape == pf.shape, (path, df.shape, pf.shape)
        assert len(df) > 0, path
        prov = df.attrs.get("weft")
        assert prov and prov["tool"] == "weft" and prov["stage"], (path, df.attrs)
        # The same provenance in the Parquet key-value metadata, for every reader.
        assert b"weft.provenance" in pq.read_metadata(path).metadata, path
        if hasattr(pl, "read_parquet_metadata"):
            assert '"tool":"weft"' in pl.read_parquet_metadata(path)["weft.provenance"], path
        expect = RESULT_EXPECT.get(path.name) if folder == out and path.name in RESULT_EXPECT else EXPECT.get(path.name, {})
        if folder == model:
            expect = expect | {c: t for c, t in OPTIONAL.get(path.name, {}).items() if c in df.columns}
        for col, dtype in expect.items():
            assert col in df.columns, f"{path}: missing {col}; has {list(df.columns)}"
            ok = pd.api.types.is_string_dtype(df[col]) if dtype == "string" else str(df[col].dtype) == dtype
            assert ok, f"{path}: {col} is {df[col].dtype}, expected {dtype}"
        checked += 1

if open_only:
    print(f"read_tables.py: {checked} tables opened in pandas and polars")
    sys.exit(0)

h = pl.read_parquet(out / "history.parquet")
assert h["t"].is_sorted(), "history is ordered by time"
assert h.group_by("t").len()["len"].n_unique() == 1, "every sample has the same nodes"
s = pd.read_parquet(out / "summary.parquet")
assert s["steps"][0] > 0 and s["dt"][0] > 0

# Round trip: tables rewritten by pandas and polars are read by weft-simulate.
m2 = scratch / "model_rewritten"
shutil.copytree(model, m2, dirs_exist_ok=True)
nodes = pd.read_parquet(m2 / "nodes.parquet")
nodes.to_parquet(m2 / "nodes.parquet")  # pandas default: snappy
parts = pl.read_parquet(m2 / "parts.parquet")
parts.write_parquet(m2 / "parts.parquet")  # polars default: zstd, string views
loads = pl.read_parquet(m2 / "loads.parquet").with_columns(pl.col("fx") * 2.0)
loads.write_parquet(m2 / "loads.parquet", compression="gzip")
r = subprocess.run([sim, "--model", str(m2), "--out", str(scratch / "out2"), "--quiet"],
                   capture_output=True, text=True)
assert r.returncode == 0, r.stderr
h2 = pl.read_parquet(scratch / "out2" / "history.parquet")
# The doubled load doubles the (linear) response.
a = h.filter(pl.col("node_id") == h["node_id"].max())["ux"].abs().max()
b = h2.filter(pl.col("node_id") == h2["node_id"].max())["ux"].abs().max()
assert abs(b / a - 2.0) < 1e-6, (a, b)
print(f"read_tables.py: {checked} tables opened in pandas and polars; rewritten tables accepted")
