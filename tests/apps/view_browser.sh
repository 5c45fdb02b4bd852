#!/usr/bin/env bash
# voxbreast view end to end (docs/VIEW.md): a small CT simulation (the bundled phantom CT at a 6 mm
# lattice, relaxation, surfaces and frames) shown in headless chromium, its rendered surface
# compared with the .vtp read by VTK, its CT page with the warped CT's NIfTI header; the static
# export served by a plain HTTP server; a real probe's and sweep's numbers; the DICOM input CT
# converted for the page; path traversal, methods and a missing token refused. Skips (77) only when chromium or the page's npm
# packages are missing (scripts/setup.sh installs both).
#   VOXBREAST_BIN=build/apps/voxbreast bash tests/apps/view_browser.sh .   [VIEW_SCREENSHOTS=docs/img]
set -uo pipefail
root=$(cd "${1:?source dir}" && pwd)
bin=${VOXBREAST_BIN:?path to voxbreast}
source "$(dirname "$0")/lib.sh"
web=$root/apps/web
chromium=${CHROMIUM:-/usr/bin/chromium}
[[ -x $chromium ]] || { echo "SKIP: $chromium is not installed (scripts/setup.sh installs Debian's chromium)"; exit 77; }
[[ -d $web/node_modules/puppeteer-core ]] || { echo "SKIP: apps/web/node_modules is missing (scripts/setup.sh runs npm ci)"; exit 77; }
py=/usr/bin/python3
# Starts `voxbreast view ARGS...` in the background; sets $url from the line it prints.
start_view() { start_server 100 view "$@"; }
status_of() { curl -s -o "$work/body" -w '%{http_code}' --path-as-is "$@"; }

# --- a small CT simulation: prone, 6 mm lattice, surfaces and frames, a tracked point
cat >"$work/scene.toml" <<TOML
[model]
image = "$root/data-samples/phantom/ct.nii.gz"
labels = "$root/data-samples/phantom/labels.nii.gz"
spacing = 0.006
keep = ["skin", "adipose", "fibroglandular", "muscle", "tumour"]
[model.label_table]
1 = "skin"
2 = "adipose"
3 = "fibroglandular"
4 = "muscle"
5 = "bone"
6 = "tumour"
[materials.muscle]
rigid = true
[solver]
integrator = "relaxation"
[gravity]
posture = "prone"
[[track]]
name = "tumour_1"
point = [0.015, -0.02, 0.01]
[output]
surfaces = true
frames_every = 100
warped_ct_dicom = false
[stop]
equilibrium = 1e-4
max_steps = 3000
TOML
out=$work/run
t0=$SECONDS
"$bin" simulate "$work/scene.toml" --out "$out" --quiet >"$work/simulate.log" 2>&1
rc=$?
if [[ $rc -eq 0 || $rc -eq 3 ]] && [[ -f $out/surface.vtp && -f $out/warped_ct.nii.gz ]]; then
  pass "small CT simulation for the page ($((SECONDS - t0)) s)"
else
  fail "small CT simulation (exit $rc)"; cat "$work/simulate.log"; finish; exit
fi

# What the page must show, read by VTK and nibabel, not by the page's own reader.
"$py" - "$out" "$work/expected.json" <<'PY'
import json, sys, re, os
import nibabel as nib
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
out, dest = sys.argv[1:]
r = vtkXMLPolyDataReader(); r.SetFileName(os.path.join(out, "surface.vtp")); r.Update()
mesh = r.GetOutput(); b = mesh.GetBounds()
frames = len(re.findall(r"<DataSet ", open(os.path.join(out, "surface.pvd")).read()))
s = json.load(open(os.path.join(out, "summary.json")))
arrows = len(s["tracked"]) + (1 if (s.get("positioning") or {}).get("tumour") else 0)
json.dump({"surface": {"vertices": mesh.GetNumberOfPoints(), "triangles": mesh.GetNumberOfPolys(),
                       "bbox_min": [b[0], b[2], b[4]], "bbox_max": [b[1], b[3], b[5]], "frames": frames, "arrows": arrows},
           "ct": {"dims": list(nib.load(os.path.join(out, "warped_ct.nii.gz")).shape[:3])},
           "tables": ["summary.json", "metrics.csv"]}, open(dest, "w"))
PY
[[ -f $work/expected.json ]] && pass "expectations from VTK and nibabel" || fail "expectations from VTK and nibabel"

# --- the page in chromium
shots=${VIEW_SCREENSHOTS:-}
if start_view "$out" --port 0; then
  pass "view prints its URL ($url)"
  if node "$root/tests/apps/view_browser.mjs" "$url" "$work/expected.json" $shots >"$work/browser.txt" 2>&1; then
    pass "simulate folder in chromium: $(grep -c '^ok' "$work/browser.txt") checks"
  else
    fail "simulate folder in chromium"
  fi
  cat "$work/browser.txt"

  # --- what the server refuses
  base=${url%/}
  ln -s /etc/passwd "$out/leak.json"
  for path in "/data/../../../../etc/passwd" "/data/%2e%2e/%2e%2e/%2e%2e/etc/passwd" "/data/..%2f..%2f..%2fetc%2fpasswd" \
              "/data/frames/%2e%2e/%2e%2e/scene.toml" "/data/leak.json" "/../../etc/passwd" "/%2e%2e/%2e%2e/etc/passwd"; do
    code=$(status_of "$base$path")
    if [[ $code =~ ^(400|403|404)$ ]] && ! grep -q "root:" "$work/body"; then pass "refused $path ($code)"; else fail "served $path ($code)"; fi
  done
  code=$(status_of "$base/data/result.h5"); [[ $code == 404 ]] && pass "a file the page does not read is not served (404)" || fail "result.h5 served ($code)"
  code=$(status_of -X POST "$base/manifest.json"); [[ $code == 405 ]] && pass "POST refused (405)" || fail "POST answered $code"
  code=$(status_of "$base/data/summary.json"); [[ $code == 200 ]] && grep -q '"elements"' "$work/body" && pass "summary.json served" || fail "summary.json ($code)"
else
  fail "view did not start"
fi

# --- --host: a random token on every request
if start_view "$out" --port 0 --host 127.0.0.2; then
  token=${url##*token=}; base=${url%%\?*}; base=${base%/}
  [[ ${#token} -eq 32 ]] && pass "--host prints a 128-bit token" || fail "token '$token'"
  code=$(status_of "$base/manifest.json"); [[ $code == 401 ]] && pass "no token: refused (401)" || fail "no token: $code"
  code=$(status_of "$base/manifest.json?token=0123456789abcdef0123456789abcdef"); [[ $code == 401 ]] && pass "wrong token: refused (401)" || fail "wrong token: $code"
  code=$(status_of -c "$work/cookies" "$base/?token=$token"); [[ $code == 200 ]] && pass "token in the URL: served" || fail "token in the URL: $code"
  code=$(status_of -b "$work/cookies" "$base/data/summary.json"); [[ $code == 200 ]] && pass "the page's cookie carries the token" || fail "cookie: $code"
  code=$(status_of -H "Authorization: Bearer $token" "$base/manifest.json"); [[ $code == 200 ]] && pass "Authorization: Bearer token" || fail "bearer: $code"
else
  fail "view --host did not start"
fi

# --- --ct: the input CT as a DICOM series, converted to NIfTI for the page: the same grid and
# values (within the 1 HU of rounding) as the phantom's own NIfTI copy
if start_view "$out" --port 0 --ct "$root/data-samples/phantom/dicom"; then
  base=${url%/}
  if [[ $(status_of "$base/manifest.json") == 200 ]] && grep -q '"input_ct":"input/ct.nii.gz"' "$work/body" \
     && [[ $(status_of "$base/input/ct.nii.gz") == 200 ]] && cp "$work/body" "$work/input_ct.nii.gz" \
     && "$py" - "$work/input_ct.nii.gz" "$root/data-samples/phantom/ct.nii.gz" <<'PY'
import sys, numpy as np, nibabel as nib
a, b = (nib.load(p) for p in sys.argv[1:])
assert a.shape == b.shape and np.allclose(a.affine, b.affine, atol=1e-3), (a.shape, b.shape, a.affine, b.affine)
assert np.abs(np.asarray(a.dataobj, float) - np.asarray(b.dataobj, float)).max() <= 1.0
PY
  then pass "--ct DICOM series served as NIfTI with the CT's grid and values"
  else fail "--ct DICOM series"; fi
else
  fail "view --ct did not start"
fi

# --- bad input: one line, non-zero exit
for args in "$work/missing" "$out --host example.org" "$out --port 70000" "$out --export $out"; do
  # shellcheck disable=SC2086
  "$bin" view $args >"$work/bad.txt" 2>&1; rc=$?
  if [[ $rc -ne 0 ]] && [[ $(wc -l <"$work/bad.txt") -eq 1 ]]; then pass "refused: view $args"; else fail "view $args (exit $rc)"; cat "$work/bad.txt"; fi
done

# --- the static export, served by a plain HTTP server
rm -f "$out/leak.json"
if "$bin" view "$out" --export "$work/export" >"$work/export.txt" 2>&1 && [[ -f $work/export/index.html && -f $work/export/data/surface.vtp ]] \
   && "$py" -c 'import json,sys; m=json.load(open(sys.argv[1])); assert m["kind"]=="simulate" and "data/surface.vtp" in m["files"]' "$work/export/manifest.json"; then
  pass "export writes the page, its files and manifest.json"
  port=$("$py" -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  (cd "$work/export" && exec "$py" -m http.server "$port" --bind 127.0.0.1 >/dev/null 2>&1) &
  servers+=($!)
  sleep 1
  "$py" -c 'import json,sys; e=json.load(open(sys.argv[1])); e["tables"]=["summary.json"]; json.dump(e, open(sys.argv[1],"w"))' "$work/expected.json"
  if node "$root/tests/apps/view_browser.mjs" "http://127.0.0.1:$port/" "$work/expected.json" >"$work/export-browser.txt" 2>&1; then
    pass "exported folder in chromium from python3 -m http.server"
  else
    fail "exported folder in chromium"; cat "$work/export-browser.txt"
  fi
else
  fail "export"; cat "$work/export.txt"
fi

# --- the numbers of a probe folder and a sweep folder (a small block: seconds each)
{ block_scene | sed 's/^max = \[0.01, 0.01, 0.01\]/max = [0.016, 0.012, 0.01]/'
  printf '[solver]\nintegrator = "relaxation"\n[[indenter]]\nkind = "capsule"\nradius = 0.003\nlength = 0.004\naxis = [0, 1, 0]\n'
  printf '[probe]\nfrom = [0.003, 0.004, 0.05]\nto = [0.013, 0.004, 0.05]\npresses = 3\ndepth = 0.001\nsteps = 2\n'
} >"$work/probe.toml"
if "$bin" probe "$work/probe.toml" --out "$work/probe" --quiet >"$work/probe.txt" 2>&1 && start_view "$work/probe" --port 0; then
  echo '{"surface": null, "ct": null, "tables": ["Force–depth curves and force profile", "probe_summary.json", "probe_curves.csv"], "shot_suffix": "_probe"}' >"$work/probe.json"
  if node "$root/tests/apps/view_browser.mjs" "$url" "$work/probe.json" $shots >"$work/probe-browser.txt" 2>&1; then
    pass "probe folder in chromium: force-depth curves, summary and tables"
  else fail "probe folder in chromium"; cat "$work/probe-browser.txt"; fi
else fail "probe folder"; cat "$work/probe.txt"; fi
block_scene >"$work/block.toml"
if "$bin" sweep "$work/block.toml" --vary materials.soft.E=2000,3000,4000 --out "$work/sweep" -q >"$work/sweep.txt" 2>&1 \
   && start_view "$work/sweep" --port 0; then
  echo '{"surface": null, "ct": null, "tables": ["Metrics against materials.soft.E", "Plots", "metrics.csv"], "shot_suffix": "_sweep"}' >"$work/sweep.json"
  if node "$root/tests/apps/view_browser.mjs" "$url" "$work/sweep.json" $shots >"$work/sweep-browser.txt" 2>&1; then
    pass "sweep folder in chromium: metrics against the parameter, its PNGs and tables"
  else fail "sweep folder in chromium"; cat "$work/sweep-browser.txt"; fi
else fail "sweep folder"; cat "$work/sweep.txt"; fi

finish
