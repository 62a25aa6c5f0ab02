#!/usr/bin/env python3
"""Write pipelines/ballistic_limit.toml: the ballistic limit of 1, 2, 4 and 8 layers.

    python3 scripts/ballistic_limit.py > pipelines/ballistic_limit.toml          (the default)
    python3 scripts/ballistic_limit.py --yarns 30 --membrane-length 0.15 \\
        --layers 1,2,4,8,16 --estimates 60,95,125,160,200 > pipelines/ballistic_limit.toml

A pipeline's sweep values are literal, so each layer count's striking velocities (fixed
fractions of an estimate of its limit, which `weft-ballistic search` gives) are written
out here. The estimates of the default are the limits its own search found
(docs/studies/ballistic_limit.md).
"""
import argparse

FRACTIONS = [0.7, 0.85, 0.95, 1.05, 1.15, 1.4, 1.8, 2.5]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--yarns", type=int, default=15, help="yarns per side of the quarter patch")
    ap.add_argument("--yarn-model", default="chain", choices=["chain", "band"])
    ap.add_argument("--membrane-length", type=float, default=0.1,
                    help="half-size of the membrane around the patch [m]")
    ap.add_argument("--failure-strain", type=float, default=0.036)
    ap.add_argument("--layers", default="1,2,4,8")
    ap.add_argument("--estimates", default="50,83,112,145",
                    help="an estimate of each layer count's limit [m/s]")
    ap.add_argument("--end-time", type=float, default=1.5e-3,
                    help="the longest an impact may need to be decided [s]")
    a = ap.parse_args()
    layers = [int(x) for x in a.layers.split(",")]
    est = [float(x) for x in a.estimates.split(",")]
    if len(layers) != len(est):
        ap.error("one estimate per layer count")
    shots = [(n, round(f * v)) for n, v in zip(layers, est) for f in FRACTIONS]
    foreach = ",\n  ".join(f"{{ layers = {n}, velocity = {v} }}" for n, v in shots)
    areal = 0.1946  # kg/m² per layer of the default weave (weft-weave woven's note)
    print(f'''# The ballistic limit of an aramid plain weave against the 9 mm, 8 g round-nose bullet,
# for 1, 2, 4 and 8 layers: the yarn-level patch ({a.yarn_model}s, {a.yarns} × {a.yarns} yarns a
# quarter, failing at {a.failure_strain}) tied into the paper's §3 membrane out to
# {a.membrane_length} m (a layer each: the far field of a large panel, which cannot fail),
# each striking velocity an impact of its own, run to its outcome; then the Lambert–Jonas
# fit and the probability of perforation per layer count (weft-ballistic), and figures.
#
#   weft run pipelines/ballistic_limit.toml        (from the project root; about 6 min on 2 cores)
#   weft run pipelines/ballistic_limit.toml --executor slurm    (each impact a task of a job array)
#   python3 -c "import polars as pl; print(pl.read_parquet('runs/ballistic_limit/limit/ballistic_limit.parquet'))"
#
# Written by scripts/ballistic_limit.py (the velocities are literal): to scale up, e.g. a
# larger patch and 16 layers, with the estimates `weft-ballistic search` gives for it:
#   python3 scripts/ballistic_limit.py --yarns 30 --membrane-length 0.15 \\
#       --layers 1,2,4,8,16 --estimates 60,95,125,160,200 > pipelines/ballistic_limit.toml
# (docs/studies/ballistic_limit.md: the measured limits, their cost, and how they scale out).

[vars]
out = "runs/ballistic_limit"
yarns = {a.yarns}
yarn_model = "{a.yarn_model}"
membrane = {a.membrane_length}
failure_strain = {a.failure_strain}
end_time = {a.end_time}

[stages.weave]
desc = "the patch of N layers in its membrane, yarns failing, runs ending at their outcome"
cmd = """weft-weave woven --yarns ${{yarns}} --yarn-model ${{yarn_model}} --layers ${{layers}} \\
  --failure-strain ${{failure_strain}} --membrane-length ${{membrane}} --end-time ${{end_time}} \\
  --stop-on-outcome --out ${{outputs.model}}"""
matrix = {{ layers = [{", ".join(str(n) for n in layers)}] }}
outputs = {{ model = "${{out}}/models/${{layers}}" }}

[stages.impact]
desc = "one impact at one striking velocity, to its outcome (perforated or arrested)"
cmd = """weft-simulate --quiet --model ${{inputs.model}} --projectile-velocity ${{velocity}} \\
  --history-set axis_x --out ${{outputs.run}}"""
foreach = [
  {foreach}
]
inputs = {{ model = "${{out}}/models/${{layers}}" }}
outputs = {{ run = "${{out}}/impacts/${{layers}}/${{velocity}}" }}

[stages.gather]
desc = "every impact's summary in one table, with its layers and velocity"
cmd = "weft gather pipelines/ballistic_limit.toml --stage impact --table summary.parquet --out ${{outputs.table}}"
inputs = {{ runs = "${{out}}/impacts" }}
outputs = {{ table = "${{out}}/impacts.parquet" }}

[stages.limit]
desc = "per layer count: the Lambert–Jonas fit (bootstrap intervals) and V50"
cmd = "weft-ballistic fit --table ${{inputs.table}} --by layers --out ${{outputs.fit}}"
inputs = {{ table = "${{out}}/impacts.parquet" }}
outputs = {{ fit = "${{out}}/limit" }}

[stages.figures]
desc = "V_r against V_s with the fits, energy absorbed, probability of perforation, V50 against areal density"
cmd = """mkdir -p ${{outputs.figs}} && \\
  weft-plot ballistic --runs ${{inputs.fit}}/ballistic_runs.parquet --limit ${{inputs.fit}}/ballistic_limit.parquet --kind residual \\
    --title 'Residual velocity, ${{yarn_model}}s: 1, 2, 4, 8 layers' --out ${{outputs.figs}}/residual.png && \\
  weft-plot ballistic --runs ${{inputs.fit}}/ballistic_runs.parquet --limit ${{inputs.fit}}/ballistic_limit.parquet --kind energy \\
    --title 'Energy absorbed by the fabric (quarter model)' --out ${{outputs.figs}}/energy.png && \\
  weft-plot ballistic --runs ${{inputs.fit}}/ballistic_runs.parquet --limit ${{inputs.fit}}/ballistic_limit.parquet --kind probability \\
    --title 'Probability of perforation' --out ${{outputs.figs}}/probability.png && \\
  weft-plot ballistic --runs ${{inputs.fit}}/ballistic_runs.parquet --limit ${{inputs.fit}}/ballistic_limit.parquet --kind limit \\
    --x-factor {areal} --x-label 'areal density [kg/m²]' --title 'Ballistic limit against areal density' --out ${{outputs.figs}}/limit.png"""
inputs = {{ fit = "${{out}}/limit" }}
outputs = {{ figs = "${{out}}/figures" }}''')


if __name__ == "__main__":
    main()
