#!/usr/bin/env bash
# Starts graspsim-server on its built-in defaults, runs the Python demo against it, stops the server with
# SIGTERM (it drains and exits 0), and fails if either the demo or the server's exit fails.
set -euo pipefail
server=${1:?usage: run-demo.sh SERVER_BINARY PYTHON}
python=${2:?usage: run-demo.sh SERVER_BINARY PYTHON}
top=$(cd "$(dirname "$0")/.." && pwd)
log=$(mktemp -t graspsim-demo-server.XXXXXX.log)

"$server" > "$log" 2>&1 &
pid=$!
stop_server() {
  kill -TERM "$pid" 2>/dev/null || true
  wait "$pid"
}
trap 'kill -TERM "$pid" 2>/dev/null || true' EXIT

demo_status=0
"$python" "$top/clients/python/examples/demo.py" --server 127.0.0.1:50051 || demo_status=$?
server_status=0
stop_server || server_status=$?
trap - EXIT
if [[ $demo_status -ne 0 || $server_status -ne 0 ]]; then
  echo "demo exit code $demo_status, server exit code $server_status; server log ($log):" >&2
  tail -n 30 "$log" >&2
  exit 1
fi
rm -f "$log"
