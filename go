#!/usr/bin/env bash
# One entry point for a fresh clone: every command first makes sure .venv exists and is current.
#   ./go team [ARGS]       a 4-agent team over Zenoh, as separate processes (launch_team.py)
#   ./go test [ARGS]       ruff, the import contracts and the test suite (what CI runs)
#   ./go run ARGS          anicov run ... (one team in process)
#   ./go reproduce ARGS    anicov reproduce ... (the paper's experiments)
#   ./go bench             the benchmarks in bench/
#   ./go setup             only create or update .venv
#   ./go maps              fetch the public SLAM maps of scenarios/real/ (./go test does)
set -euo pipefail
cd "$(dirname "$0")"
VENV=.venv
PY=${PYTHON:-python3}

setup() {
    local stamp="$VENV/.installed-from"
    local want
    want=$(sha256sum pyproject.toml | cut -d' ' -f1)
    if [[ ! -x "$VENV/bin/python" ]]; then
        echo "go: creating $VENV" >&2
        "$PY" -m venv "$VENV"
    fi
    if [[ ! -f "$stamp" || "$(cat "$stamp")" != "$want" ]]; then
        echo "go: installing anicov and its dependencies into $VENV" >&2
        "$VENV/bin/python" -m pip install --quiet --upgrade pip >&2
        "$VENV/bin/python" -m pip install --quiet -e '.[test]' >&2
        echo "$want" > "$stamp"
    fi
}

command=${1:-help}
shift || true
case "$command" in
    setup) setup ;;
    test)
        setup
        scenarios/real/fetch_maps.sh  # the public SLAM maps the tests read (from Debian's registry; not committed)
        "$VENV/bin/ruff" check .
        "$VENV/bin/lint-imports"  # the layout's contracts (pyproject.toml [tool.importlinter])
        # On every core, up to 4 (pytest-xdist): every test stands alone (free ports, unique team names and
        # namespaces), and one process at a time took 11.6 min from a fresh clone on 2 cores, 8.5 on both.
        # ARGS come after, so `./go test -n 0` runs in one process.
        exec "$VENV/bin/python" -m pytest -n auto --maxprocesses 4 "$@"
        ;;
    team) setup; exec "$VENV/bin/python" launch_team.py --n 4 "$@" ;;
    run) setup; exec "$VENV/bin/anicov" run "$@" ;;
    reproduce) setup; exec "$VENV/bin/anicov" reproduce "$@" ;;
    bench) setup; exec "$VENV/bin/python" bench/run_all.py "$@" ;;
    maps) exec scenarios/real/fetch_maps.sh ;;
    *) sed -n '2,10p' "$0"; exit 2 ;;
esac
