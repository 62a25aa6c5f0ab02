#!/usr/bin/env python3
"""Which modelling choice moves a thick pack's ballistic limit at armour velocity.

One base shot (a quarter of 24 plies of aramid chains, 12 x 12 yarns failing at 0.036, in
the paper's §3 membrane out to 0.1 m, in air, struck at 398 m/s by the rigid 8 g round
nose, run to its outcome), then one change at a time: the mesh, the failure
regularisations, yarn friction, the far field's shear stiffness, the span, the patch, the
yarns' strain-rate strengthening, the deformable bullet, the yarns as bands (membranes
across their width, in contact on their lenticular faces) instead of truss chains. Each case gives the residual
velocity v_r and the ballistic limit it implies by Lambert & Jonas with p = 2 (a rigid
projectile whose lost kinetic energy is the pack's), V_bl = sqrt(v_s^2 - v_r^2), the
whole pack's absorbed energy (4 x the quarter's), the plies perforated, the books and
the wall time. Writes <out>/pack_physics.parquet and prints the table of
docs/ballistic_convergence.md, "At armour velocity".

    python3 scripts/pack_physics.py --bin target/release --out runs/pack_physics

Every case is a folder of its own under <out>; a case whose summary exists is not run
again (delete the folder to rerun it). About 30 min on 2 cores.
"""
import argparse
import math
import os
import subprocess
import sys

import pyarrow as pa
import pyarrow.parquet as pq

# Kevlar 49 fabric strips (ICF13, Beijing 2013, paper 389; docs/theory.md, "Rate
# dependence"): the failure strain 2.92 % at 30 1/s and 3.66 % at 170 1/s, so
# eps_f(rate) = 0.0292 (1 + C ln(rate/30)) with C = (3.66/2.92 - 1)/ln(170/30) = 0.146.
RATE_C = (3.66 / 2.92 - 1.0) / math.log(170.0 / 30.0)
RATE = [
    "--failure-strain", "0.0292",
    "--failure-rate-coefficient", repr(RATE_C),
    "--failure-reference-rate", "30",
]

# (name, group, weft-weave flags changed from the base)
CASES = [
    ("default", "base", []),
    ("8 elements a spacing", "mesh", ["--per-spacing", "8"]),
    ("failure delay 0", "numerical", ["--failure-delay", "0"]),
    (
        "delay 0 and damping 0",
        "numerical",
        ["--failure-delay", "0", "--projectile-contact-damping", "0"],
    ),
    ("yarn friction 0", "physical", ["--friction", "0"]),
    ("yarn friction 0.3", "physical", ["--friction", "0.3"]),
    ("membrane G/E 0.05", "physical", ["--membrane-shear-ratio", "0.05"]),
    ("membrane to 0.2 m (panel 0.4 m)", "physical", ["--membrane-length", "0.2"]),
    ("patch 24 yarns", "physical", ["--yarns", "24"]),
    ("rate law (Kevlar 49 strips)", "physical", RATE),
    ("failure strain 0.045", "physical", ["--failure-strain", "0.045"]),
    ("FMJ bullet", "physical", ["--projectile", "deformable", "--bullet", "fmj"]),
    ("band yarns", "physical", ["--yarn-model", "band"]),
]


def run(cmd, log):
    with open(log, "w") as f:
        r = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT)
    if r.returncode != 0:
        sys.exit(f"pack_physics: `{' '.join(cmd)}` failed (exit {r.returncode}); see {log}")


def base_flags(a):
    return [
        "--yarns", str(a.yarns), "--yarn-model", "chain", "--layers", str(a.plies),
        "--failure-strain", "0.036", "--membrane-length", "0.1",
        "--projectile-velocity", str(a.velocity), "--end-time", str(a.end_time),
        "--output-interval", "1e-5", "--stop-on-outcome",
    ]


def merged(base, flags):
    """The base flags with each flag of `flags` replacing the base's value."""
    out, i = list(base), 0
    while i < len(flags):
        name = flags[i]
        value = flags[i + 1] if i + 1 < len(flags) and not flags[i + 1].startswith("--") else None
        if name in out:
            j = out.index(name)
            if value is not None:
                out[j + 1] = value
        else:
            out += [name] + ([value] if value is not None else [])
        i += 2 if value is not None else 1
    return out


def one_case(a, name, flags, folder):
    os.makedirs(folder, exist_ok=True)
    model, shot = os.path.join(folder, "model"), os.path.join(folder, "shot")
    summary = os.path.join(shot, "summary.parquet")
    if not os.path.exists(summary):
        weave = [os.path.join(a.bin, "weft-weave"), "woven"] + merged(base_flags(a), flags)
        run(weave + ["--out", model], os.path.join(folder, "weave.log"))
        sim = [os.path.join(a.bin, "weft-simulate"), "--model", model, "--out", shot]
        run(sim, os.path.join(folder, "simulate.log"))
    s = pq.read_table(summary).to_pylist()[0]
    vr = s["residual_velocity"] if s["perforated"] else 0.0
    vs = s["striking_velocity"]
    # The bullet's speed at the end from the kinetic energy it lost (the quarter's share
    # of both): a deformable bullet with fragments riding on it may stay undecided.
    lost = 2.0 * s["energy_absorbed"] / s["projectile_mass"]
    v_end = math.sqrt(max(vs * vs - lost, 0.0))
    wall = sum(s[k] or 0.0 for k in s if k.startswith("wall_time_"))
    return {
        "case": name,
        "flags": " ".join(flags),
        "outcome": s["outcome"],
        "outcome_time": s["outcome_time"],
        "plies_perforated": s["plies_perforated"],
        "residual_velocity": vr,
        "speed_at_end": v_end,
        "v_bl": math.sqrt(max(vs * vs - vr * vr, 0.0)) if s["perforated"] else None,
        "energy_absorbed": 4.0 * s["energy_absorbed"],
        "balance": s["max_balance_error_relative"],
        "wall": wall,
    }


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--bin", default="target/release", help="folder of the weft binaries")
    p.add_argument("--out", default="runs/pack_physics", help="folder of the cases")
    p.add_argument("--plies", type=int, default=24)
    p.add_argument("--yarns", type=int, default=12)
    p.add_argument("--velocity", type=float, default=398.0)
    p.add_argument("--end-time", type=float, default=4e-4)
    p.add_argument("--cases", default="", help="comma-separated groups or case names (all)")
    a = p.parse_args()
    want = [c for c in a.cases.split(",") if c]
    rows = []
    for i, (name, group, flags) in enumerate(CASES):
        if want and group not in want and name not in want:
            continue
        rows.append(one_case(a, name, flags, os.path.join(a.out, f"{i:02d}")))
        r = rows[-1]
        print(f"{name}: {r['outcome']} at {1e6 * (r['outcome_time'] or 0):.0f} us, "
              f"v_r {r['residual_velocity']:.0f} m/s, {r['plies_perforated']} plies, "
              f"{r['energy_absorbed']:.1f} J, balance {r['balance']:.1e}, wall {r['wall']:.0f} s",
              flush=True)
    pq.write_table(pa.Table.from_pylist(rows), os.path.join(a.out, "pack_physics.parquet"))
    base = next((r for r in rows if r["case"] == "default"), None)
    print("\n| case | outcome | v_r [m/s] | V_bl [m/s] | vs default | speed at the end [m/s] "
          "| energy [J] | plies perforated | balance | wall [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        rel = ""
        if base and base["v_bl"] and r["v_bl"]:
            rel = f"{100 * (r['v_bl'] / base['v_bl'] - 1):+.1f} %"
        vbl = f"{r['v_bl']:.0f}" if r["v_bl"] else "–"
        vr = f"{r['residual_velocity']:.0f}" if r["v_bl"] else "–"
        print(f"| {r['case']} | {r['outcome']} | {vr} | {vbl} | {rel} | {r['speed_at_end']:.0f} | "
              f"{r['energy_absorbed']:.1f} | {r['plies_perforated']} | {r['balance']:.1e} | {r['wall']:.0f} |")


if __name__ == "__main__":
    main()
