#!/usr/bin/env bash
# The spread of the ballistic limit over draws of the yarn strengths: one model per seed
# (2 layers of the 15-yarn chain quarter in a 0.1 m membrane, Weibull modulus 14 per
# yarn, the scale at the aramid's 0.036), each searched to a 2 m/s bracket by
# weft-ballistic search; plus the same model without scatter ("det").
#
#   scripts/ballistic_seeds.sh [OUT] [SEEDS] [PARALLEL] [THREADS]
#       OUT       output folder (runs/ballistic_seeds); OUT/<seed>/ballistic_limit.parquet
#       SEEDS     how many seeds (16)
#       PARALLEL  searches at once (1); THREADS  each search's threads (all cores)
#
# On 16 cores (4 searches of 4 threads at once) the 17 searches took 6 min, 66–94 s each
# (docs/studies/ballistic_limit.md). Then:
#   python3 -c "import polars as pl; print(pl.read_parquet('runs/ballistic_seeds/*/ballistic_limit.parquet', include_file_paths='path').select('path','v50','v_bl'))"
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-runs/ballistic_seeds}
SEEDS=${2:-16}
PARALLEL=${3:-1}
THREADS=${4:-$(nproc)}
BIN=${WEFT_BIN:-target/release}
export OUT BIN THREADS
one() {
    s=$1
    d=$OUT/$s
    mkdir -p "$d"
    if [ "$s" = det ]; then extra=(); else extra=(--weibull-modulus 14 --seed "$s"); fi
    "$BIN/weft-weave" woven --yarns 15 --yarn-model chain --layers 2 --failure-strain 0.036 \
        "${extra[@]}" --membrane-length 0.1 --end-time 1.5e-3 --stop-on-outcome \
        --out "$d/model" >"$d/weave.log" 2>&1
    "$BIN/weft-ballistic" search --model "$d/model" --lo 50 --hi 110 --tolerance 2 \
        --per-round 4 --threads "$THREADS" --out "$d" >"$d/search.log" 2>&1
    grep "V50" "$d/search.log" | sed "s/^/$s: /"
}
export -f one
{ echo det; seq 1 "$SEEDS"; } | xargs -P "$PARALLEL" -I{} bash -c 'one {}'
