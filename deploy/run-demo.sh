#!/usr/bin/env bash
# Starts graspsim-server on its built-in defaults, runs the Python demo (and the Octave one) against it, stops the server with
# SIGTERM (it drains and exits 0), and fails if either the demo or the server's exit fails.
set -euo pipefail
server=${1:?usage: run-demo.sh SERVER_BINARY PYTHON}
python=${2:?usage: run-demo.sh SERVER_BINARY PYTHON}
top=$(cd "$(dirname "$0")/.." && pwd)
log=$(mktemp -t graspsim-demo-server.XXXXXX.log)
# The demo's scenes go to a store of this run, not the user's (~/.local/share/graspsim): each run creates its
# scenes anew, and runs must not pile them up in the user's store (docs/durability.md).
data=$(mktemp -d -t graspsim-demo-data.XXXXXX)

"$server" --data-dir="$data" > "$log" 2>&1 &
pid=$!
stop_server() {
  kill -TERM "$pid" 2>/dev/null || true
  wait "$pid"
}
trap 'kill -TERM "$pid" 2>/dev/null || true' EXIT

demo_status=0
"$python" "$top/clients/python/examples/demo.py" --server 127.0.0.1:50051 --http http://127.0.0.1:8080 \
  --server-binary "$server" || demo_status=$?
# The same job from GNU Octave through the HTTP/JSON gateway (the Matlab client), when Octave is installed.
if [[ $demo_status -eq 0 ]] && command -v octave >/dev/null; then
  echo
  echo "--- the same scene from GNU Octave (clients/matlab) ---"
  # Octave 7.3 prints "ignoring const execution_exception" at exit after any webwrite: its own noise, dropped.
  octave --no-gui --no-window-system --quiet --eval \
    "addpath('$top/clients/matlab', '$top/clients/matlab/examples'); graspsim_demo('http://127.0.0.1:8080');" \
    2> >(grep -v 'ignoring const execution_exception' >&2) || demo_status=$?
fi
server_status=0
stop_server || server_status=$?
trap - EXIT
if [[ $demo_status -ne 0 || $server_status -ne 0 ]]; then
  echo "demo exit code $demo_status, server exit code $server_status; server log ($log):" >&2
  tail -n 30 "$log" >&2
  exit 1
fi
rm -f "$log"
rm -rf "$data"
