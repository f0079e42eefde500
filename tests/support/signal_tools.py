"""Small signal-analysis helpers shared by the Python test tools (numpy only)."""

import numpy as np


def isolated_codes(x, threshold):
    """Rows where one sample stands off its neighbours by more than threshold while the
    neighbourhood (two samples either side) is quiet: the neighbours agree with each other and
    with their own neighbours to within a quarter of it. A fast load change or a bounce moves the
    neighbours too, a converter glitch does not."""
    p = np.pad(np.asarray(x, dtype=float), 2, mode="edge")
    c = p[2:-2]
    left1, right1, left2, right2 = p[1:-3], p[3:-1], p[:-4], p[4:]
    off = np.abs(c - 0.5 * (left1 + right1)) > threshold
    quiet = 0.25 * threshold
    agree = ((np.abs(right1 - left1) < quiet) & (np.abs(left1 - left2) < quiet)
             & (np.abs(right2 - right1) < quiet))
    idx = np.nonzero(off & agree)[0]
    return idx[(idx > 0) & (idx < len(c) - 1)]


def moving_average(x, width):
    kernel = np.ones(width) / width
    padded = np.pad(x, (width // 2, width - 1 - width // 2), mode="edge")
    return np.convolve(padded, kernel, mode="valid")


def ls_periodogram(t, x, freqs):
    """Power of the best cos+sin fit at each frequency (least squares, uneven t allowed)."""
    x = x - x.mean()
    arg = 2.0 * np.pi * np.outer(freqs, t - t[0])
    c, s = np.cos(arg), np.sin(arg)
    cc, ss, cs = (c * c).sum(1), (s * s).sum(1), (c * s).sum(1)
    xc, xs = c @ x, s @ x
    det = cc * ss - cs * cs
    a = (xc * ss - xs * cs) / det
    b = (xs * cc - xc * cs) / det
    return a * xc + b * xs


def robust_sigma(x):
    """Standard deviation of Gaussian data from the median absolute deviation."""
    return 1.4826 * float(np.median(np.abs(x - np.median(x))))


def mvv_per_unit(meta):
    """mV/V worth one unit of the b columns, from the `converter` / `bridge_unit` metadata."""
    conv = meta.get("converter")
    if not conv:
        unit = meta.get("bridge_unit", "mV/V")
        if unit != "mV/V":
            raise ValueError(f"bridge unit {unit} needs a converter description")
        return 1.0
    keys = dict(item.strip().split("=", 1) for item in conv.split(","))
    bits = int(keys["bits"])
    coding = keys.get("coding", "signed")
    k = bits if coding == "unsigned" else bits - 1
    if "full_scale_mvv" in keys:
        return float(keys["full_scale_mvv"]) / 2 ** k
    if keys.get("ratiometric", "yes") != "yes":
        raise ValueError("a non-ratiometric converter needs full_scale_mvv here")
    return 1000.0 * float(keys.get("reference_ratio", 1.0)) / float(keys.get("gain", 1.0)) / 2 ** k
