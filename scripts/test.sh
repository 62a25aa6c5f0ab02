#!/usr/bin/env bash
# The whole test suite on a fresh machine, every oracle required: the structure checks
# (scripts/checks.sh: function and file sizes, import circles), then installs what the tests
# need (CalculiX for the exported decks, a single-node Slurm for the Slurm executor,
# pandas, polars, pyarrow and VTK for the read-back tests: with pip, or in .venv-test/
# where the system's Python is externally managed), starts Slurm, runs
# `cargo test --release` and stops Slurm again, even on failure. `.ci/run` is this script.
#
#   scripts/test.sh                  everything (root or sudo for apt-get)
#   scripts/test.sh --test woven     arguments go to cargo test
#
# Without this script `cargo test --release` runs too: the tests of a missing tool are
# reported as ignored (with a SKIPPED line naming it) instead of failing.
set -euo pipefail
cd "$(dirname "$0")/.."
# The structure checks first: seconds, before any install or build (scripts/checks.sh).
scripts/checks.sh
export CARGO_TERM_COLOR=never
SUDO=$([ "$(id -u)" = 0 ] || echo sudo)
# pandas, polars and pyarrow for tests/read_tables.py (the pandas/polars read test and
# the docs' python blocks); vtk (VTK's own XML readers, as ParaView uses them) for
# tests/read_vtk.py. Where the system's Python is externally managed (Debian 12, Ubuntu
# 24.04: pip refuses to install into it), they go into a virtual environment,
# .venv-test/, whose python3 comes first on PATH for the tests.
PY_PACKAGES="pandas polars pyarrow vtk"
if ! python3 -c "import pandas, polars, pyarrow, vtkmodules" 2>/dev/null; then
    if [ -x .venv-test/bin/python3 ] || ! python3 -m pip install --quiet --disable-pip-version-check \
            --root-user-action=ignore $PY_PACKAGES 2>/dev/null; then
        if [ ! -x .venv-test/bin/python3 ]; then
            python3 -m venv .venv-test 2>/dev/null || {
                $SUDO apt-get update -qq && $SUDO apt-get install -y -qq python3-venv python3-pip
                python3 -m venv .venv-test
            }
        fi
        export PATH="$PWD/.venv-test/bin:$PATH"
        python3 -m pip install --quiet --disable-pip-version-check $PY_PACKAGES
    fi
fi
# CalculiX (ccx 2.20) runs the decks of weft-export in tests/export_calculix.rs; the
# package lists may be empty on a fresh machine, hence the update.
if ! command -v ccx >/dev/null; then
    $SUDO apt-get update -qq && $SUDO apt-get install -y -qq calculix-ccx
fi
# A single-node Slurm (Debian: slurmctld slurmd slurm-client munge) for
# tests/pipeline_slurm.rs; its daemons are stopped by PID when this script exits.
if ! command -v slurmctld >/dev/null || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
    scripts/slurm-single-node.sh install
fi
trap 'scripts/slurm-single-node.sh stop' EXIT
scripts/slurm-single-node.sh start
export WEFT_REQUIRE_PYTHON=1 WEFT_REQUIRE_CCX=1 WEFT_REQUIRE_SLURM=1
cargo test --release "$@"
