#!/usr/bin/env bash
# Bit-identity check between two builds of weft: runs every generator at its defaults
# (and simulates each model, the hexahedra's Taylor rod among them) and the shipped
# pipelines with each build, then compares every Parquet table they write (models,
# results, fits, errors, wave speeds, figures' data) value by value, ignoring the Parquet
# metadata (provenance names the tool version and paths) and the wall-time columns.
#
#   scripts/bit_identity.sh [--full] BEFORE AFTER
#
# Without --full: the generators except the 60 x 60 woven impact (generated and compared,
# not simulated) and the pipelines rod_waves and girder_membrane (minutes). With --full:
# the woven impact simulated too and every pipeline in pipelines/ (about an hour a build
# on 2 cores). WEFT_BITID_PIPELINES="rod_waves woven_patch" chooses the pipelines instead.
#
# BEFORE and AFTER are each a folder of built binaries (e.g. target/release) or a git
# revision, which is checked out in a temporary worktree and built (release) into
# target/bit-identity/<rev>. Needs python3 with pyarrow. Exit 0 when every table is
# identical, 1 with a list of differences otherwise.
set -euo pipefail
full=0
if [ "${1:-}" = "--full" ]; then full=1; shift; fi
root="$(cd "$(dirname "$0")/.." && pwd)"
work="$(mktemp -d "${TMPDIR:-/tmp}/weft-bitid.XXXXXX")"
trap 'rm -rf "$work"' EXIT

bins() { # $1: folder or revision -> prints a folder of binaries
  if [ -x "$1/weft-simulate" ]; then (cd "$1" && pwd); return; fi
  local rev; rev="$(git -C "$root" rev-parse --verify "$1^{commit}")" || {
    echo "error: \`$1\` is neither a folder with weft binaries nor a git revision" >&2; exit 2; }
  local wt="$work/src-${rev:0:12}" tgt="$root/target/bit-identity/${rev:0:12}"
  git -C "$root" worktree add --detach --quiet "$wt" "$rev"
  (cd "$wt" && CARGO_TARGET_DIR="$tgt" cargo build --release --quiet --bins) >&2
  git -C "$root" worktree remove --force "$wt"
  echo "$tgt/release"
}

run_all() { # $1: binaries, $2: output folder
  local b="$1" o="$2"
  mkdir -p "$o"
  for g in rod girder membrane combined woven-reduced woven taylor; do
    "$b/weft-weave" "$g" --out "$o/models/$g" >/dev/null 2>&1
    if [ "$g" != woven ] || [ "$full" = 1 ]; then
      "$b/weft-simulate" --quiet --model "$o/models/$g" --out "$o/gen/$g" --threads 2 >/dev/null 2>&1
    fi
  done
  mkdir -p "$o/study"
  cp -r "$root/pipelines" "$o/study/"
  local pipes="${WEFT_BITID_PIPELINES:-rod_waves girder_membrane}"
  [ "$full" = 1 ] && pipes="$(cd "$root/pipelines" && ls *.toml | sed 's/\.toml$//')"
  for p in $pipes; do
    (cd "$o/study" && "$b/weft" run --quiet "pipelines/$p.toml" >/dev/null 2>"$o/$p.log") || {
      echo "error: pipeline $p failed with $b (log: $o/$p.log)" >&2; cat "$o/$p.log" >&2; exit 2; }
  done
}

before="$(bins "$1")"; after="$(bins "$2")"
echo "before: $before" >&2; echo "after:  $after" >&2
run_all "$before" "$work/before"
run_all "$after" "$work/after"

python3 - "$work/before" "$work/after" <<'PY'
import sys, pathlib, pyarrow.parquet as pq
a, b = map(pathlib.Path, sys.argv[1:3])
skip_cols = lambda c: "wall" in c or "per_second" in c or c in ("file", "path", "seconds", "threads")
files = sorted(p.relative_to(a) for p in a.rglob("*.parquet") if ".weft" not in p.parts)
bad, n = [], 0
for rel in files:
    pb = b / rel
    if not pb.exists():
        bad.append(f"{rel}: missing after"); continue
    ta, tb = pq.read_table(a / rel), pq.read_table(pb)
    cols = [c for c in ta.column_names if not skip_cols(c)]
    if cols != [c for c in tb.column_names if not skip_cols(c)]:
        bad.append(f"{rel}: columns differ"); continue
    ta, tb = ta.select(cols).replace_schema_metadata(None), tb.select(cols).replace_schema_metadata(None)
    if not ta.equals(tb):
        diff = [c for c in cols if not ta[c].equals(tb[c])]
        bad.append(f"{rel}: {ta.num_rows} / {tb.num_rows} rows, columns differ: {diff}")
    n += 1
from collections import Counter
kinds = Counter(r.name if r.parent.name != "speeds" else "speeds/*.parquet" for r in files)
print("compared: " + ", ".join(f"{v} {k}" for k, v in sorted(kinds.items())))
print(f"bit identity: {n} tables compared, {len(bad)} differ")
for x in bad:
    print("  " + x)
sys.exit(1 if bad or n == 0 else 0)
PY
