#!/usr/bin/env bash
# voxbreast serve end to end (docs/VIEW.md, "Live simulation"): a block streamed to a WebSocket
# client; the frame paused at step 1000 equals `simulate` run to step 1000 (its surface.vtp, read
# by VTK); a gravity change moves the streamed surface; malformed, unknown and oversized controls
# are refused while the run goes on; a missing token is refused; the live page in headless
# chromium shows frames without console errors. Skips (77) only without chromium or the page's npm
# packages (scripts/setup.sh installs both).
#   VOXBREAST_BIN=build/apps/voxbreast bash tests/apps/serve_live.sh .
set -uo pipefail
root=$(cd "${1:?source dir}" && pwd)
bin=${VOXBREAST_BIN:?path to voxbreast}
source "$(dirname "$0")/lib.sh"
web=$root/apps/web
[[ -x ${CHROMIUM:-/usr/bin/chromium} ]] || { echo "SKIP: chromium is not installed (scripts/setup.sh installs it)"; exit 77; }
[[ -d $web/node_modules/ws ]] || { echo "SKIP: apps/web/node_modules is missing (scripts/setup.sh runs npm ci)"; exit 77; }
py=/usr/bin/python3
start_serve() { start_server 300 serve "$@"; }

{ block_scene; printf '[solver]\ncheck_every = 50\n'; } >"$work/block.toml"
if start_serve "$work/block.toml" --port 0 --pause-at-step 1000; then
  pass "serve prints its URL ($url)"
  if node "$root/tests/apps/serve_live.mjs" "$url" "$work/paused.json" >"$work/client.txt" 2>&1; then
    pass "stream: $(grep -c '^ok' "$work/client.txt") checks"
  else fail "stream"; fi
  cat "$work/client.txt"
  # The same scene by simulate, stopped at the same step.
  if "$bin" simulate "$work/block.toml" --out "$work/sim" --quiet --set +stop.max_steps=1000 --set +stop.equilibrium=0 \
       --set +output.surfaces=true >"$work/sim.txt" 2>&1 \
     && "$py" - "$work/sim/surface.vtp" "$work/paused.json" <<'PY'
import json, sys
import numpy as np
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
from vtkmodules.util.numpy_support import vtk_to_numpy
r = vtkXMLPolyDataReader(); r.SetFileName(sys.argv[1]); r.Update()
expected = vtk_to_numpy(r.GetOutput().GetPoints().GetData())
frame = json.load(open(sys.argv[2]))
streamed = np.array(frame["positions_mm"]).reshape(-1, 3)
assert frame["step"] == 1000, frame["step"]
assert streamed.shape == expected.shape, (streamed.shape, expected.shape)
err = np.abs(streamed - expected).max()
print(f"max difference {err:.2e} mm over {len(expected)} vertices")
assert err < 1e-4, err
PY
  then pass "the frame paused at step 1000 equals simulate's surface at step 1000"
  else fail "paused frame against simulate"; cat "$work/sim.txt"; fi
else
  fail "serve did not start"
fi

# Exposed with --host: the WebSocket needs the token too.
if start_serve "$work/block.toml" --port 0 --host 127.0.0.2; then
  token=${url##*token=}; base=${url%%\?*}; base=${base%/}
  code=$(curl -s -o /dev/null -w '%{http_code}' "$base/manifest.json")
  [[ $code == 401 ]] && pass "serve --host: no token refused (401)" || fail "serve --host without token: $code"
  ws_status() {  # HTTP status of a WebSocket handshake (101: switched)
    curl -s -o /dev/null -m 3 -w '%{http_code}' -H "Connection: Upgrade" -H "Upgrade: websocket" \
      -H "Sec-WebSocket-Version: 13" -H "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==" "$@"
  }
  code=$(ws_status "$base/live"); [[ $code != 101 ]] && pass "WebSocket without token refused ($code)" || fail "WebSocket without token: 101"
  code=$(ws_status -H "Authorization: Bearer $token" "$base/live"); [[ $code == 101 ]] && pass "WebSocket with the token accepted" || fail "WebSocket with the token: $code"
else
  fail "serve --host did not start"
fi

# The live page in chromium.
if start_serve "$work/block.toml" --port 0; then
  echo '{"live": true}' >"$work/live.json"
  if node "$root/tests/apps/view_browser.mjs" "$url" "$work/live.json" >"$work/live-browser.txt" 2>&1; then
    pass "live page in chromium: $(grep -c '^ok' "$work/live-browser.txt") checks"
  else fail "live page in chromium"; fi
  cat "$work/live-browser.txt"
fi

"$bin" serve "$work/missing.toml" >"$work/bad.txt" 2>&1; rc=$?
[[ $rc -ne 0 && $(wc -l <"$work/bad.txt") -eq 1 ]] && pass "missing scene refused in one line" || { fail "missing scene (exit $rc)"; cat "$work/bad.txt"; }
finish
