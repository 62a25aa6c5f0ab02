#!/usr/bin/env python3
"""How the ballistic limit and the energy absorbed at 400 m/s move with each modelling
choice: the mesh, the time-step safety, the failure delay, the projectile's contact
damping, friction, the span (the membrane's length) and the yarn-level patch's size.

One base model (a quarter of one ply of aramid chains, 8 x 8 yarns, failing at 0.036, in
the paper's §3 membrane out to 0.05 m, struck by the 8 g round nose), then one change at a
time: `weft-ballistic search` brackets its V50 to --tolerance, and one impact at 400 m/s
gives the energy it absorbs (the quarter model's share of the bullet's lost kinetic
energy, x 4 for the whole panel). Writes <out>/sensitivity.parquet (one row per case) and
prints the table of docs/verification.md, "Sensitivity of the ballistic limit".

    python3 scripts/sensitivity.py --bin target/release --out runs/sensitivity
    python3 scripts/sensitivity.py --bin target/release --out runs/sensitivity --layers 4 \
        --cases mesh --lo 40 --hi 120

Every case is a folder of its own under <out>; a case whose limit table exists is not
run again (delete the folder to rerun it).
"""
import argparse
import os
import subprocess
import sys

import pyarrow as pa
import pyarrow.parquet as pq

# The regularisations off: no failure delay, no contact damping at the nose.
OFF = ["--failure-delay", "0", "--projectile-contact-damping", "0"]

# (name, group, weft-weave flags changed from the base). The default failure delay is ten
# element transits (0.335 us on the default mesh), the contact damping 0.5.
CASES = [
    ("default", "mesh", []),
    ("8 elements a spacing", "mesh", ["--per-spacing", "8"]),
    ("16 elements a spacing", "mesh", ["--per-spacing", "16"]),
    ("nonlocal: 4 elements a spacing", "nonlocal", ["--failure-length", "0.001"] + OFF),
    (
        "nonlocal: 8 elements a spacing",
        "nonlocal",
        ["--failure-length", "0.001", "--per-spacing", "8"] + OFF,
    ),
    (
        "nonlocal: 16 elements a spacing",
        "nonlocal",
        ["--failure-length", "0.001", "--per-spacing", "16"] + OFF,
    ),
    ("time-step safety 0.45", "numerical", ["--dt-safety", "0.45"]),
    ("failure delay x2", "numerical", ["--failure-delay", "6.708203932499369e-07"]),
    ("failure delay x1/2", "numerical", ["--failure-delay", "1.6770509831248424e-07"]),
    ("failure delay 0", "numerical", ["--failure-delay", "0"]),
    ("contact damping 0", "numerical", ["--projectile-contact-damping", "0"]),
    ("contact damping 1", "numerical", ["--projectile-contact-damping", "1"]),
    (
        "delay 0 and damping 0",
        "numerical",
        ["--failure-delay", "0", "--projectile-contact-damping", "0"],
    ),
    ("yarn friction 0", "physical", ["--friction", "0"]),
    ("yarn friction 0.3", "physical", ["--friction", "0.3"]),
    ("projectile friction 0", "physical", ["--projectile-friction", "0"]),
    ("membrane to 0.025 m (panel 0.05 m)", "physical", ["--membrane-length", "0.025"]),
    ("membrane to 0.1 m (panel 0.2 m)", "physical", ["--membrane-length", "0.1"]),
    ("patch 15 yarns", "physical", ["--yarns", "15"]),
]


def run(cmd, log):
    with open(log, "w") as f:
        r = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT)
    if r.returncode != 0:
        sys.exit(f"sensitivity: `{' '.join(cmd)}` failed (exit {r.returncode}); see {log}")


def one_case(a, name, flags, folder):
    os.makedirs(folder, exist_ok=True)
    model = os.path.join(folder, "model")
    limit = os.path.join(folder, "limit", "ballistic_limit.parquet")
    fast = os.path.join(folder, "v400", "summary.parquet")
    if not (os.path.exists(limit) and os.path.exists(fast)):
        args = {
            "--yarns": str(a.yarns), "--yarn-model": "chain", "--layers": str(a.layers),
            "--failure-strain": "0.036", "--membrane-length": "0.05", "--end-time": "0.0015",
        }
        args.update(dict(zip(flags[::2], flags[1::2])))
        cmd = [os.path.join(a.bin, "weft-weave"), "woven", "--stop-on-outcome"]
        for k, v in args.items():
            cmd += [k, v]
        run(cmd + ["--out", model], os.path.join(folder, "weave.log"))
        run(
            [
                os.path.join(a.bin, "weft-ballistic"), "search", "--model", model,
                "--lo", str(a.lo), "--hi", str(a.hi), "--tolerance", str(a.tolerance),
                "--out", os.path.join(folder, "limit"),
            ],
            os.path.join(folder, "search.log"),
        )
        run(
            [
                os.path.join(a.bin, "weft-simulate"), "--quiet", "--model", model,
                "--projectile-velocity", "400", "--out", os.path.join(folder, "v400"),
            ],
            os.path.join(folder, "v400.log"),
        )
    lim = pq.read_table(limit).to_pylist()[0]
    s = pq.read_table(fast).to_pylist()[0]
    m, v0 = s["projectile_mass"], s["striking_velocity"]
    vr = s["residual_velocity"] if s["perforated"] else 0.0
    return {
        "case": name,
        "v50": lim["v50"],
        "v50_lo": lim["v50_low"],
        "v50_hi": lim["v50_high"],
        "v_bl": lim["v_bl"],
        "energy_400": 4.0 * 0.5 * m * (v0 * v0 - vr * vr),
        "perforated_400": bool(s["perforated"]),
        "failed_400": s["failed_elements"],
        "balance_400": s["max_balance_error_relative"],
    }


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--bin", default="target/release", help="folder of the weft binaries")
    p.add_argument("--out", default="runs/sensitivity")
    p.add_argument("--layers", type=int, default=1)
    p.add_argument("--yarns", type=int, default=8)
    p.add_argument("--lo", type=float, default=15.0)
    p.add_argument("--hi", type=float, default=80.0)
    p.add_argument("--tolerance", type=float, default=1.0)
    p.add_argument(
        "--cases", default="mesh,nonlocal,numerical,physical", help="groups to run"
    )
    a = p.parse_args()
    groups = a.cases.split(",")
    rows = []
    for name, group, flags in CASES:
        if group not in groups:
            continue
        if name == "patch 15 yarns" and a.yarns != 8:
            continue
        slug = "".join(c if c.isalnum() or c in ".-" else "_" for c in name)
        folder = os.path.join(a.out, f"{a.layers}ply", slug)
        r = one_case(a, name, flags, folder)
        r.update(group=group, layers=a.layers)
        rows.append(r)
        print(f"{name}: V50 {r['v50']:.1f} m/s, E(400) {r['energy_400']:.2f} J", file=sys.stderr)
    base = rows[0]
    print("| case | V50 [m/s] | vs default | energy at 400 m/s [J] | vs default |")
    print("|---|---|---|---|---|")
    for r in rows:
        dv = 100 * (r["v50"] / base["v50"] - 1)
        de = 100 * (r["energy_400"] / base["energy_400"] - 1)
        print(
            f"| {r['case']} | {r['v50']:.1f} ({r['v50_lo']:.1f}–{r['v50_hi']:.1f}) "
            f"| {dv:+.1f} % | {r['energy_400']:.2f} | {de:+.1f} % |"
        )
    path = os.path.join(a.out, f"sensitivity_{a.layers}ply.parquet")
    tmp = path + ".tmp"
    pq.write_table(pa.Table.from_pylist(rows), tmp)
    os.replace(tmp, path)


if __name__ == "__main__":
    main()
