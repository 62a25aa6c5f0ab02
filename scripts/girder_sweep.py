#!/usr/bin/env python3
"""Write pipelines/girder_sweep.toml: the paper's §4 sweep of girder parameters x.

    python3 scripts/girder_sweep.py > pipelines/girder_sweep.toml                (the default)
    python3 scripts/girder_sweep.py --cells 4,6,8,10,12,14 --ratios 7 \\
        --combined-cells 12,16 --membrane-cells 4,8 > pipelines/girder_sweep.toml   (larger)

A pipeline's sweep values are literal, so the grid (and the closed forms beside each
point, which --expected needs as numbers) is written out here rather than computed in TOML.
"""
import argparse
import math

L, E, RHO_G = 0.1, 1.5e11, 7800.0
T = L * math.sqrt(RHO_G / E)          # tension pulse period (the girder_membrane.toml choice)
PERIODS = {"tension": T, "shear": 40 * T}


def g_name(n, k, n_r):
    return f"g{n}-r{k}" if k < n_r else f"heldout-g{n}"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cells", default="5,6,7,8,9,10", help="N_g of the same-mesh sweep")
    ap.add_argument("--ratios", type=int, default=5,
                    help="b/a values, log-spaced over the paper's 1/20..1/8 (eq. 3)")
    ap.add_argument("--combined-cells", default="12,16",
                    help="N_g of the combined sweep (multiples of 4; two or more for its surrogate)")
    ap.add_argument("--membrane-cells", default="4,8",
                    help="N_m of the combined sweep (multiples of 4: the zone's edges at L/4, 3L/4)")
    ap.add_argument("--starts", type=int, default=4, help="dynamic multistart starts")
    ap.add_argument("--evaluations", type=int, default=400, help="dynamic evaluations per start")
    ap.add_argument("--heldout", default="7,0.085",
                    help="the held-out x: N_g,b/a (not in the training grid)")
    ap.add_argument("--restarts", type=int, default=5, help="network initialisations per (n1, activation)")
    a = ap.parse_args()
    hn, hr = a.heldout.split(",")
    hn, hr = int(hn), float(hr)
    cells = [int(c) for c in a.cells.split(",")]
    ccells = [int(c) for c in a.combined_cells.split(",") if c]
    mcells = [int(c) for c in a.membrane_cells.split(",") if c]
    n_r = a.ratios
    ratios = [(1 / 20) * (2.5 ** (k / (n_r - 1))) if n_r > 1 else 0.1 for k in range(n_r)]

    girders = sorted(set((n, k) for n in cells + ccells for k in range(n_r)))
    ratios.append(hr)          # index n_r: the held-out ratio
    girders.append((hn, n_r))
    membranes = sorted(set(cells + [hn]))
    for n in ccells + mcells:
        if n % 4:
            ap.error(f"--combined-cells and --membrane-cells must be multiples of 4 (got {n}): "
                     "the girder zone's edges lie at L/4 and 3L/4 on both grids")
    # One fit instance per (x, approach): same-mesh (N_m = N_g, all nodes) and combined
    # (the Fig. 5b model: N_m membrane cells around a girder zone of N_g; the zone's
    # nodes compared). Both match the girder's nodes by position.
    fits = []
    for n in cells:
        for k in range(n_r):
            fits.append((n, k, n, "same-mesh", "reference", f"membrane/{n}"))
    for n in ccells:
        for k in range(n_r):
            for m in mcells:
                fits.append((n, k, m, "combined", "centre", f"combined/{g_name(n, k, n_r)}-m{m}"))

    def g(n, k):
        return g_name(n, k, n_r)

    out = []
    w = out.append
    w(f"""# The paper's §4, second half: the membrane y = {{G_m, s_m, ρ_m}} fitted to girders over a
# grid of x, gathered into one table x → y, T (the remaining mismatch Δ) with the lattice
# closed forms beside (docs/theory.md, "Closed forms used as oracles": s = b²/a, ρ = ρ_g(2 − b/a), G = E(b/a)²/2), then the
# regression and network surrogates of x → y (weft-surrogate) and the paper's Fig. 6b.
#
#   weft run pipelines/girder_sweep.toml       (from the project root)
#
# Written by scripts/girder_sweep.py (the sweep values are literal): to scale up, e.g.
#   python3 scripts/girder_sweep.py --cells 4,6,8,10,12,14 --ratios 7 \\
#       --combined-cells 12,16 --membrane-cells 4,8 > pipelines/girder_sweep.toml
#
# Grid: N_g = {cells}, b/a = {', '.join(f'{r:.4f}' for r in ratios)} (log-spaced over
# the paper's eq. 3 range 1/20..1/8; b_g = (b/a)·L/N_g); L = 0.1 m, E = 150 GPa,
# ρ_g = 7800 kg/m³, b = h, joints rigid, clamp holding translations (girder_membrane.toml).
# - same mesh (x = {{b_g, N_g}}): the membrane on the girder's nodes, all nodes compared;
# - combined (x = {{b_g, N_m, N_g}}, the paper's Fig. 5b): a membrane of N_m = {mcells}
#   cells per side with a girder zone L/2 × L/2 at its centre (the rods of the girder of
#   N_g = {ccells} cells, tied to the membrane around it; `weft-weave membrane
#   --girder-cells`), fitted so that the zone's nodes move as the full girder's central
#   zone does (`--set centre`, matched by position; the paper's reference nodes).
# Each x is fitted statically ({{G, s}}; ρ does not enter a static solve, from a poor start)
# and then dynamically ({{G, s, ρ}}, {a.starts} starts × {a.evaluations} evaluations) from the
# static fit's membranes (G and s fitted, ρ still the poor start): from the poor start
# itself the dynamic T is multi-extremal and a short multistart stops at T ≈ 0.48 with G
# at 13–80 × its closed form (measured). Tension and shear are fitted together.

[vars]
out = "runs/girder_sweep"
start = "--shear-modulus 2e9 --thickness 1e-3 --density 5000"
params = "--param membrane.G12:1e7:1e11:log --param membrane.s:1e-6:1e-2:log"
""")
    w("[stages.girder]")
    w('desc = "the girders, both load cases"')
    w('cmd = "weft-weave girder --cells ${cells} --rod-width ${b} --clamp translations --load-case ${case} --period ${period} --out ${outputs.model}"')
    w("foreach = [")
    for n, k in girders:
        b = ratios[k] * L / n
        for case, p in PERIODS.items():
            w(f'  {{ name = "{g(n, k)}", cells = {n}, b = {b:.10e}, case = "{case}", period = {p:.15e} }},')
    w("]")
    w('outputs = { model = "${out}/girder/${name}/${case}" }\n')

    w("[stages.membrane]")
    w('desc = "the start membranes, both load cases"')
    w('cmd = "weft-weave membrane --cells ${cells} --load-case ${case} --period ${period} ${start} --out ${outputs.model}"')
    w("foreach = [")
    for n in membranes:
        for case, p in PERIODS.items():
            w(f'  {{ cells = {n}, case = "{case}", period = {p:.15e} }},')
    w("]")
    w('outputs = { model = "${out}/membrane/${cells}/${case}" }\n')

    combos = sorted(set((n, k, m) for n, k, m, approach, _, _ in fits if approach == "combined"))
    if combos:
        w("[stages.combined]")
        w('desc = "the combined models (Fig. 5b): the start membrane of N_m cells around the girder zone, both load cases"')
        w('cmd = "weft-weave membrane --cells ${N_m} --girder-cells ${N_g} --rod-width ${b} --load-case ${case} --period ${period} ${start} --out ${outputs.model}"')
        w("foreach = [")
        for n, k, m in combos:
            b = ratios[k] * L / n
            for case, p in PERIODS.items():
                w(f'  {{ name = "{g(n, k)}", N_g = {n}, N_m = {m}, b = {b:.10e}, case = "{case}", period = {p:.15e} }},')
        w("]")
        w('outputs = { model = "${out}/combined/${name}-m${N_m}/${case}" }\n')

    w("[stages.girder_run]")
    w('desc = "the girders\' static solve and explicit run"')
    w('cmd = "weft-simulate --quiet ${flag} --model ${inputs.model} --out ${outputs.run}"')
    w("foreach = [")
    for n, k in girders:
        for case in PERIODS:
            for mode, flag in [("static", "--static --threads 1"), ("dynamic", "--threads 1")]:
                w(f'  {{ name = "{g(n, k)}", case = "{case}", mode = "{mode}", flag = "{flag}" }},')
    w("]")
    w('inputs = { model = "${out}/girder/${name}/${case}" }')
    w('outputs = { run = "${out}/runs/${name}/${mode}-${case}" }\n')

    def fit_stages(prefix, fits, where):
        for mode in ["static", "dynamic"]:
            w(f"[stages.{prefix}_{mode}]")
            if mode == "static":
                w(f'desc = "{where}: the membrane\'s {{G, s}} fitted statically (ρ does not enter a static solve)"')
                extra = "--static"
            else:
                w(f'desc = "{where}: the membrane\'s {{G, s, ρ}} fitted dynamically from the static fit (multistart)"')
                extra = (f"--param membrane.rho:1e3:1e5:log --expected membrane.rho=${{rho_cf}} "
                         f"--starts {a.starts} --max-evaluations {a.evaluations}")
            w(f'''cmd = """weft-fit --quiet --threads 1 --components ux,uy --set ${{set}} ${{params}} {extra} \\
  --expected membrane.G12=${{G_cf}} --expected membrane.s=${{s_cf}} \\
  --reference-model ${{inputs.gt}} --reference-history ${{inputs.rt}}/history.parquet --model ${{inputs.mt}} \\
  --reference-model ${{inputs.gs}} --reference-history ${{inputs.rs}}/history.parquet --model ${{inputs.ms}} \\
  --out ${{outputs.fit}}"""''')
            w("foreach = [")
            for n, k, m, approach, st, initial in fits:
                r = ratios[k]
                b = r * L / n
                fit = f"{g(n, k)}-m{m}" if approach == "same-mesh" else f"{g(n, k)}-zone-m{m}"
                w(f'  {{ name = "{g(n, k)}", fit = "{fit}", approach = "{approach}", N_g = {n}, b_g = {b:.10e}, '
                  f'ratio = {r:.10e}, N_m = {m}, set = "{st}", initial = "{initial}", '
                  f'G_cf = {E * r * r / 2:.10e}, s_cf = {r * r * L / n:.10e}, rho_cf = {RHO_G * (2 - r):.10e} }},')
            w("]")
            w(f'inputs = {{ gt = "${{out}}/girder/${{name}}/tension", gs = "${{out}}/girder/${{name}}/shear", '
              f'rt = "${{out}}/runs/${{name}}/{mode}-tension", rs = "${{out}}/runs/${{name}}/{mode}-shear", '
              + ('mt = "${out}/${initial}/tension", ms = "${out}/${initial}/shear" }' if mode == "static" else
                 f'mt = "${{out}}/{prefix}/static/${{fit}}/models/tension", ms = "${{out}}/{prefix}/static/${{fit}}/models/shear" }}'))
            w(f'outputs = {{ fit = "${{out}}/{prefix}/{mode}/${{fit}}" }}\n')

    fit_stages("fit", fits, "each girder x")
    for mode in ["static", "dynamic"]:
        w(f"""[stages.gather_{mode}]
desc = "one table x → y, T ({mode} fits, both approaches), the closed forms beside: one row per fit"
cmd = "weft gather pipelines/girder_sweep.toml --stage fit_{mode} --table fit_row.parquet --out ${{outputs.table}}"
inputs = {{ fits = "${{out}}/fit/{mode}" }}
outputs = {{ table = "${{out}}/sweep_{mode}.parquet" }}
""")
    hb = hr * L / hn
    xs = f"b_g={hb:.10e},N_g={hn}"
    w(f"""[stages.surrogate]
desc = "regression and the paper's network search (n1 = 3..17 × tanh, logistic × {a.restarts} restarts) on the same-mesh dynamic fits: x = {{b_g, N_g}} → y = {{G, s, ρ}}"
cmd = "weft-surrogate train --table ${{inputs.table}} --filter approach=same-mesh --inputs b_g,N_g --outputs membrane.G12,membrane.s,membrane.rho --restarts {a.restarts} --out ${{outputs.dir}}"
inputs = {{ table = "${{out}}/sweep_dynamic.parquet" }}
outputs = {{ dir = "${{out}}/surrogate" }}

[stages.surrogate_combined]
desc = "the same on the combined-model dynamic fits (Fig. 5b): x = {{b_g, N_m, N_g}} → y = {{G, s, ρ, Δ = T}}, as the paper's §4 ends"
cmd = "weft-surrogate train --table ${{inputs.table}} --filter approach=combined --inputs b_g,N_m,N_g --outputs membrane.G12,membrane.s,membrane.rho,T --restarts {a.restarts} --out ${{outputs.dir}}"
inputs = {{ table = "${{out}}/sweep_dynamic.parquet" }}
outputs = {{ dir = "${{out}}/surrogate_combined" }}

[stages.surrogate_figure]
desc = "test MSE against n1 per activation, the regression's and the paper's (its Fig. 6b), for both surrogates"
cmd = '''mkdir -p ${{outputs.figs}} && weft-plot surrogate --search ${{inputs.dir}}/search.parquet --surrogate ${{inputs.dir}}/surrogate.json --mark 'paper: 11 tansig, 0.0333=11:0.0333' --title 'Network search, same mesh x = {{b_g, N_g}}: test MSE (normalised outputs)' --out ${{outputs.figs}}/surrogate_search.png && \\
  weft-plot surrogate --search ${{inputs.cdir}}/search.parquet --surrogate ${{inputs.cdir}}/surrogate.json --mark 'paper: 11 tansig, 0.0333=11:0.0333' --title 'Network search, combined model x = {{b_g, N_m, N_g}} → {{G, s, ρ, Δ}}: test MSE' --out ${{outputs.figs}}/surrogate_search_combined.png'''
inputs = {{ dir = "${{out}}/surrogate", cdir = "${{out}}/surrogate_combined" }}
outputs = {{ figs = "${{out}}/figures" }}

# The held-out x = (N_g = {hn}, b/a = {hr}; b_g = {hb:.6e} m), not in the training grid: the
# surrogates' prediction, the membrane the network predicts (built with the one-liner
# weft-weave membrane $$(weft-surrogate predict ... --print-flags network ...)) run against
# the girder, and a direct fit at that x (static, then dynamic) to compare with.
[stages.heldout_prediction]
desc = "both surrogates' y at the held-out x"
cmd = "weft-surrogate predict --surrogate ${{inputs.dir}}/surrogate.json --x {xs} --out ${{outputs.table}}"
inputs = {{ dir = "${{out}}/surrogate" }}
outputs = {{ table = "${{out}}/heldout/prediction.parquet" }}

[stages.heldout_membrane]
desc = "the membrane the network predicts at the held-out x"
cmd = "weft-weave membrane --cells {hn} --load-case ${{case}} --period ${{period}} $$(weft-surrogate predict --surrogate ${{inputs.dir}}/surrogate.json --x {xs} --print-flags network --flag membrane.G12=--shear-modulus --flag membrane.s=--thickness --flag membrane.rho=--density) --out ${{outputs.model}}"
foreach = [{{ case = "tension", period = {PERIODS['tension']:.15e} }}, {{ case = "shear", period = {PERIODS['shear']:.15e} }}]
inputs = {{ dir = "${{out}}/surrogate" }}
outputs = {{ model = "${{out}}/heldout/predicted/${{case}}" }}

[stages.heldout_run]
desc = "explicit run of the predicted membrane"
cmd = "weft-simulate --quiet --threads 1 --model ${{inputs.model}} --out ${{outputs.run}}"
matrix = {{ case = ["tension", "shear"] }}
inputs = {{ model = "${{out}}/heldout/predicted/${{case}}" }}
outputs = {{ run = "${{out}}/heldout/runs/${{case}}" }}

[stages.heldout_error]
desc = "T of the predicted membrane against the girder at the held-out x"
cmd = "weft-error --components ux,uy --set reference --reference-model ${{inputs.g}} --reference-history ${{inputs.gr}}/history.parquet --model ${{inputs.m}} --history ${{inputs.mr}}/history.parquet --out-dir ${{outputs.dir}}"
matrix = {{ case = ["tension", "shear"] }}
inputs = {{ g = "${{out}}/girder/{g(hn, n_r)}/${{case}}", gr = "${{out}}/runs/{g(hn, n_r)}/dynamic-${{case}}", m = "${{out}}/heldout/predicted/${{case}}", mr = "${{out}}/heldout/runs/${{case}}" }}
outputs = {{ dir = "${{out}}/heldout/error/${{case}}" }}
""")
    fit_stages("heldout_fit", [(hn, n_r, hn, "same-mesh", "reference", f"membrane/{hn}")], "the held-out x, fitted directly")
    out_txt = "\n".join(out)
    print(out_txt)


if __name__ == "__main__":
    main()
