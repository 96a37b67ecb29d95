#!/usr/bin/env bash
# Create (once) the project's virtual environment and install the package into it.
# Usage: tools/setup_env.sh [--warm-up=now|background] [EXTRAS]   e.g. tools/setup_env.sh test,docs
# Prints the path of the environment's python on its last line; pip's output goes to
# $VENV/setup.log and is shown only if a step fails.
#
# Nothing is installed when nothing changed: $VENV/.setup-stamp records a hash of pyproject.toml and
# of the environment's Python version, and the extras installed; the install runs again only when
# that hash differs or an extra is missing (so ./run.sh after ./test.sh does not reinstall).
# After an install, the numba kernels are compiled once (numba caches them on disk), so the first real
# call starts at once:
#   --warm-up=now (default): before the script returns, in two processes, one per core: a --tiny run of
#     the main job then the coadjoint kernels (tools/warm_kernels.py --part mechanics), and beside them
#     the rough-path kernels (--part roughpaths);
#   --warm-up=background (./run.sh, which runs the main job next and so compiles the main job's kernels
#     itself): the script returns at once and one background process compiles the rough-path, then the
#     coadjoint kernels (log: $VENV/warm-up.log; its pid is in $VENV/.warm-up.pid until it ends).
# A warm-up that did not finish (interrupted) is done again by the next call.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="${VENV:-.venv}"
WARM_MODE=now
case "${1:-}" in
    --warm-up=now|--warm-up=background) WARM_MODE="${1#--warm-up=}"; shift ;;
    --warm-up=*) echo "setup_env.sh: unknown warm-up mode '${1#--warm-up=}' (use --warm-up=now or --warm-up=background)" >&2; exit 2 ;;
esac
EXTRAS="${1:-}"
PY="$VENV/bin/python"
STAMP="$VENV/.setup-stamp"
PENDING="$VENV/.warm-up-pending"          # an install whose warm-up has not finished yet
PID_FILE="$VENV/.warm-up.pid"             # a background warm-up still running

digest() {  # sha256 of stdin, with whatever the system has
    if command -v sha256sum >/dev/null 2>&1; then sha256sum | cut -d' ' -f1
    elif command -v shasum >/dev/null 2>&1; then shasum -a 256 | cut -d' ' -f1
    else python3 -c 'import hashlib, sys; print(hashlib.sha256(sys.stdin.buffer.read()).hexdigest())'
    fi
}
# the inputs of an install: the package metadata and the environment's Python version
inputs_hash() { { cat pyproject.toml; grep -i '^version' "$VENV/pyvenv.cfg" 2>/dev/null || true; } | digest; }
# "a,b" -> "a b" sorted, unique, without empties
norm_extras() { tr ', ' '\n\n' <<<"$1" | sed '/^$/d' | sort -u | tr '\n' ' ' | sed 's/ $//'; }

warm_running() { [ -f "$PID_FILE" ] && kill -0 "$(cat "$PID_FILE")" 2>/dev/null; }

# Compile the numba kernels once (cached on disk by numba): the main job's, at tiny sizes, and the
# library's other kernels (tools/warm_kernels.py: signatures and their gradients, signature kernels, the
# Brownian tree, the coadjoint kernels); afterwards the first call of a user does not wait for the compiler.
warm_up() {
    local more=""                         # the test suite's kernels too, when the test extra is installed
    case ",$1," in *,test,*) more="--more" ;; esac
    if [ "$WARM_MODE" = background ]; then
        echo "Compiling the library's numba kernels in the background (about a minute; log: $VENV/warm-up.log) ..." >&2
        (
            start=$SECONDS
            "$PY" tools/warm_kernels.py --part roughpaths $more || echo "warning: compiling the rough-path kernels failed"
            "$PY" tools/warm_kernels.py --part mechanics $more || echo "warning: compiling the coadjoint kernels failed"
            echo "Compiled in $((SECONDS - start)) s."
            rm -f "$PENDING" "$PID_FILE"
        ) >"$VENV/warm-up.log" 2>&1 </dev/null &
        echo $! > "$PID_FILE"
        return
    fi
    if [ -n "$more" ]; then   # measured on 2 cores: 190-220 s with the suite's kernels
        echo "Compiling the numba kernels once, the test suite's too (about 3-4 minutes) ..." >&2
    else
        echo "Compiling the numba kernels once (about a minute) ..." >&2
    fi
    local start=$SECONDS warm
    warm="$(mktemp -d)"
    # Two processes, one per core: the main job's kernels (a --tiny run) then the other coadjoint kernels, and
    # beside them the rough-path kernels (signatures with gradients, signature kernels, the tree).
    (
        rc=0
        "$PY" -m mechanics --tiny --quiet --output "$warm/run" >"$warm/main.log" 2>&1 || rc=$?
        [ "$rc" -le 1 ] || echo "warning: the warm-up run failed (exit $rc, see $LOG)" >&2   # 1: a tiny-size check failed
        "$PY" tools/warm_kernels.py --part mechanics $more >>"$warm/main.log" 2>&1 \
            || echo "warning: compiling the coadjoint kernels failed (see $LOG)" >&2
    ) &
    "$PY" tools/warm_kernels.py --part roughpaths $more >"$warm/rp.log" 2>&1 \
        || echo "warning: compiling the rough-path kernels failed (see $LOG)" >&2
    wait
    cat "$warm/main.log" "$warm/rp.log" >>"$LOG"
    rm -rf "$warm"
    rm -f "$PENDING"                      # ran to its end (a failed part has warned; its kernels compile on first use)
    echo "Compiled in $((SECONDS - start)) s." >&2
}

if [ -x "$PY" ] && [ -f "$STAMP" ] && [ -x "$VENV/bin/levy-area-paper" ]; then
    stamp_hash="$(sed -n 1p "$STAMP")"
    stamp_extras="$(sed -n 2p "$STAMP")"
    missing=""
    for e in $(norm_extras "$EXTRAS"); do
        case " $stamp_extras " in *" $e "*) ;; *) missing="$missing $e" ;; esac
    done
    if [ "$stamp_hash" = "$(inputs_hash)" ] && [ -z "$missing" ]; then
        if [ -f "$PENDING" ] && ! warm_running; then   # an earlier warm-up was interrupted
            LOG="$VENV/setup.log"
            warm_up "$(tr ' ' ',' <<<"$stamp_extras")"
        fi
        echo "$PY"
        exit 0
    fi
    # install the union, so that a later call with fewer extras finds everything
    EXTRAS="$stamp_extras $EXTRAS"
fi
EXTRAS="$(norm_extras "$EXTRAS" | tr ' ' ',')"

if [ ! -x "$PY" ]; then
    echo "Creating the virtual environment $VENV (first run only) ..." >&2
    python3 -m venv "$VENV" >&2
fi
LOG="$VENV/setup.log"
: > "$LOG"
rm -f "$STAMP"
pipi() {
    if ! "$PY" -m pip install --disable-pip-version-check "$@" >>"$LOG" 2>&1; then
        echo "pip install $* failed; its output:" >&2
        tail -n 40 "$LOG" >&2
        exit 1
    fi
}
echo "Installing the package${EXTRAS:+ with extras [$EXTRAS]} into $VENV (again only when pyproject.toml changes) ..." >&2
pipi --upgrade pip setuptools wheel numpy
if [[ "$EXTRAS" == *test* || "$EXTRAS" == *bench* ]]; then
    # iisignature's setup.py imports numpy at build time: build it against the numpy above.
    "$PY" -c "import iisignature" 2>/dev/null || pipi --no-build-isolation "iisignature>=0.24"
fi
if [ -n "$EXTRAS" ]; then
    pipi -e ".[$EXTRAS]"
else
    pipi -e .
fi

{ inputs_hash; norm_extras "$EXTRAS"; } > "$STAMP"
touch "$PENDING"
warm_up "$EXTRAS"
echo "$PY"
