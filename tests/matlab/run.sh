#!/usr/bin/env bash
# End-to-end tests of the Matlab/Octave client (clients/matlab) in GNU Octave against the real server.
#
#   tests/matlab/run.sh
#
# The server binary is $GRASPSIM_SERVER, else <repo>/build/bin/graspsim-server. It is started on two free
# loopback ports (gRPC and the HTTP/JSON gateway), must answer GET /v1 within 20 s, runs the tests in
# tests/matlab/test_client.m (URL in GRASPSIM_HTTP_URL) and must exit 0 on SIGTERM. Exits non-zero when a test
# failed, the server did not start, or it did not stop cleanly. The server log is kept when something failed.
set -u
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
server="${GRASPSIM_SERVER:-$repo/build/bin/graspsim-server}"
start_timeout_s=20
stop_timeout_s=30
octave_timeout_s=900

if [[ ! -x "$server" ]]; then
  echo "graspsim-server not found at $server: build it (make) or set GRASPSIM_SERVER" >&2
  exit 2
fi
command -v octave >/dev/null || { echo "octave not found (apt-get install octave)" >&2; exit 2; }

free_port() {
  python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}
answers() {  # true once GET $1 succeeds (curl, else python3)
  if command -v curl >/dev/null; then
    curl -sf --max-time 2 "$1" >/dev/null 2>&1
  else
    python3 -c 'import sys, urllib.request; urllib.request.urlopen(sys.argv[1], timeout=2)' "$1" >/dev/null 2>&1
  fi
}
grpc_port="$(free_port)"
http_port="$(free_port)"
while [[ "$http_port" == "$grpc_port" ]]; do http_port="$(free_port)"; done
url="http://127.0.0.1:$http_port"
log="$(mktemp /tmp/graspsim-matlab-tests.XXXXXX.log)"

grasp_dir=$(mktemp -d -t graspsim-matlab-grasps.XXXXXX)  # the tests' grasp sets and scenes, never the user's store
"$server" --listen="127.0.0.1:$grpc_port" --http-listen="127.0.0.1:$http_port" --grasp-data-dir="$grasp_dir" \
  --data-dir="$grasp_dir" \
  >"$log" 2>&1 &
server_pid=$!
# never leave a server behind (interrupted runs)
trap 'kill -KILL "$server_pid" 2>/dev/null; rm -rf "$grasp_dir"' EXIT
server_rc=""
stop_server() {  # SIGTERM, then wait up to stop_timeout_s; sets server_rc to the exit code (or "timeout")
  kill -TERM "$server_pid" 2>/dev/null
  for _ in $(seq $((stop_timeout_s * 10))); do
    if ! kill -0 "$server_pid" 2>/dev/null; then
      wait "$server_pid"
      server_rc=$?
      return
    fi
    sleep 0.1
  done
  kill -KILL "$server_pid" 2>/dev/null
  wait "$server_pid" 2>/dev/null
  server_rc=timeout
}

ready=0
for _ in $(seq $((start_timeout_s * 10))); do
  if ! kill -0 "$server_pid" 2>/dev/null; then break; fi
  if answers "$url/v1"; then ready=1; break; fi
  sleep 0.1
done
if [[ $ready != 1 ]]; then
  echo "graspsim-server did not answer GET $url/v1 within ${start_timeout_s} s; log $log:" >&2
  tail -n 30 "$log" >&2
  stop_server
  exit 1
fi

echo "graspsim-server at $url (gRPC 127.0.0.1:$grpc_port); Octave tests:"
# Octave's "X11 DISPLAY" and exit-time noise on stderr is harmless: keep stderr only for the failure report.
octave_err="$(mktemp /tmp/graspsim-matlab-octave.XXXXXX.err)"
GRASPSIM_HTTP_URL="$url" timeout "$octave_timeout_s" octave --no-gui --quiet --no-window-system \
  --eval "addpath('$here'); failed = test_client(); exit(double(failed > 0));" 2>"$octave_err"
tests_rc=$?

stop_server
status=0
if [[ $tests_rc != 0 ]]; then
  echo "Octave tests failed (exit code $tests_rc; 124 = timed out after ${octave_timeout_s} s)" >&2
  grep -v -e 'DISPLAY' -e 'execution_exception' "$octave_err" | tail -n 30 >&2
  status=1
fi
if [[ "$server_rc" != 0 ]]; then
  echo "graspsim-server did not exit 0 on SIGTERM (got $server_rc); log $log:" >&2
  tail -n 30 "$log" >&2
  status=1
fi
rm -f "$octave_err"
if [[ $status == 0 ]]; then
  rm -f "$log"
  echo "server stopped cleanly (exit 0)"
else
  echo "server log kept at $log" >&2
fi
exit $status
