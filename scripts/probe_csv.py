"""CSV reading and the force profile's width, shared by plot_probe.py and palpation_sweep.py
(no matplotlib here: the sweep also runs where it is missing)."""
import csv


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def fwhm(s, y):
    """Full width at half maximum, linear interpolation (as engine/probe/force_profile.cpp)."""
    k = max(range(len(y)), key=lambda i: y[i])
    half = 0.5 * y[k]
    if not y[k] > 0:
        return 0.0
    left, right = s[0], s[-1]
    for i in range(k, 0, -1):
        if y[i - 1] < half:
            left = s[i] + (half - y[i]) / (y[i - 1] - y[i]) * (s[i - 1] - s[i])
            break
    for i in range(k, len(y) - 1):
        if y[i + 1] < half:
            right = s[i] + (half - y[i]) / (y[i + 1] - y[i]) * (s[i + 1] - s[i])
            break
    return abs(right - left)
