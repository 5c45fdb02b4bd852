#!/usr/bin/python3
"""Progress without a terminal (docs/OUTPUTS.md, "Progress"): stderr is a pipe here, so
`voxbreast simulate` prints one status line at most every --status-interval seconds, each of the
form

    voxbreast: PHASE: NN%, ~LEFT left, ELAPSED elapsed; M → TOL  step N  t=T s  residual R  speed S

with the phase named, the larger of the residual and the speed (M, what the equilibrium test
compares) against the tolerance while a run converges, and an estimate of the time left;
--quiet prints no status line at all.

Usage: check_progress.py VOXBREAST_BINARY
Runs `voxbreast phantom --spacing 4` and its scene with an unloaded reference state (two phases
that converge, then the image outputs). Exit 0 when all checks pass, 1 on a failure.
"""
import re
import subprocess
import sys
import tempfile
import time

LINE = re.compile(r"^voxbreast: (?P<phase>[a-z ]+): +(?P<percent>\d+)%, ~(?P<left>\d+(\.\d)? (s|min|h)|\?) left, "
                  r"(?P<elapsed>\d+(\.\d)? (s|min|h)) elapsed; (?P<text>.*)$")
failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def run_timed(args):
    """(exit status, [(seconds since start, stderr line)]) with stderr read as it arrives."""
    start = time.monotonic()
    process = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    lines = [(time.monotonic() - start, line.rstrip("\n")) for line in process.stderr]
    return process.wait(), lines


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    binary = sys.argv[1]
    with tempfile.TemporaryDirectory(prefix="vb_progress_") as out:
        made = subprocess.run([binary, "phantom", "--out", f"{out}/ph", "--spacing", "4"], capture_output=True)
        check(made.returncode == 0, "voxbreast phantom")
        if made.returncode != 0:
            return 1
        scene = open(f"{out}/ph/scene.toml").read()
        scene = scene.replace("[stop]", "[reference_state]\nct_posture = \"supine\"\n\n[stop]")
        scene = re.sub(r"max_steps = \d+", "max_steps = 3000", scene)
        scene = re.sub(r"equilibrium = [0-9.e-]+", "equilibrium = 1e-4", scene)
        open(f"{out}/ph/progress.toml", "w").write(scene)
        interval = 0.25
        status, lines = run_timed([binary, "simulate", f"{out}/ph/progress.toml", "--out", f"{out}/run",
                                   "--status-interval", str(interval)])
        check(status in (0, 3), f"simulate exits 0 or 3 (not converged), got {status}")
        status_lines = [(t, line) for t, line in lines if line.startswith("voxbreast: ") and "% " not in line
                        and re.search(r"\d+%, ~", line)]
        for t, line in status_lines:
            check(LINE.match(line) is not None, f"status line format: {line!r}")
        check(len(status_lines) >= 3, f"{len(status_lines)} status lines in {lines[-1][0] if lines else 0:.1f} s")
        times = [t for t, _ in status_lines]
        gaps = [b - a for a, b in zip(times, times[1:])]
        # Lines leave the process at least `interval` apart; the pipe may bunch them a little.
        check(not gaps or min(gaps) >= 0.8 * interval,
              f"status lines at least {interval} s apart (smallest gap {min(gaps) if gaps else 0:.3f} s)")
        phases = {LINE.match(line).group("phase") for _, line in status_lines if LINE.match(line)}
        print(f"      phases seen: {sorted(phases)}")
        converging = [line for _, line in status_lines if LINE.match(line) and " → " in line]
        measure = re.compile(r"; (\d\.\d\de[-+]\d+) → 1e-04 .* residual (\S+)  speed (\S+)$")
        shown = [measure.search(line) for line in converging]
        check(any(shown) and all(float(m.group(1)) == max(float(m.group(2)), float(m.group(3))) for m in shown if m),
              "a converging run shows max(residual, speed) against the tolerance (1e-04)")
        check(any(LINE.match(line).group("phase") == "reference state" for line in converging)
              or "reference state" not in phases, "the reference state's solves show their residual")

        status, lines = run_timed([binary, "simulate", f"{out}/ph/progress.toml", "--out", f"{out}/quiet", "--quiet",
                                   "--status-interval", str(interval)])
        noisy = [line for _, line in lines if LINE.match(line)]
        check(status in (0, 3) and not noisy, f"--quiet prints no status line ({len(noisy)} printed)")
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
