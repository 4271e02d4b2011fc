#!/usr/bin/env python3
"""Can the receiver's geometry bring snow back to WADS with each sensor's datasheet threshold?
(docs/weather.md, "Detection thresholds by datasheet").

    python receiver_fit.py

A restatement, in the standard library, of the flake model of ``sim::effects::weather::particles``
for one beam looking at the sky from an OS1-128 (3 mrad, intensity reference 10 m, range gate
120 m): Sekhon-Srivastava sizes of flakes of density 0.1 g/cm^3, Mitchell's projected area, the
lidar ratio of ice (29 sr), the 11 mm exit spot and the bistatic overlap of two side-by-side
apertures ``s`` apart with a receiver field ``k`` times the divergence. For a floor ``P_min`` it
integrates the rate of flakes that beat it along the beam (0.1 m steps) and prints the chance that a
beam holds one (about the share of returns that are flakes in our ``rural`` scans) and the median
range of the detectable flakes.

It prints the calibrated model (the range-gate threshold, ``s`` = 26 mm, ``k`` = 1.5), the same
receiver under the OS1's datasheet threshold (40 m at 10 %), and the receivers (``s``, ``k``) that
keep both rates' shares within 2-15 % under that threshold, best median first.
"""

from __future__ import annotations

import bisect
import math

APERTURE_M = 0.011
FLAKE_PER_MELTED = 10 ** (1 / 3)
AREA_COEFFICIENT_MM2, AREA_EXPONENT, D_MAX_MM = 0.30122, 1.88, 20.0
REFLECTANCE = 2 * math.pi / 29.0


def overlap(r: float, divergence: float, s: float, k: float) -> float:
    """The share of the beam's spot at ``r`` inside the receiver's field (particles.rs)."""
    a, b = 0.5 * (APERTURE_M + divergence * r), 0.5 * (APERTURE_M + k * divergence * r)
    if s >= a + b:
        return 0.0
    if s <= abs(b - a):
        return (min(a, b) / a) ** 2
    alpha = math.acos(max(-1.0, min(1.0, (s * s + a * a - b * b) / (2 * s * a))))
    beta = math.acos(max(-1.0, min(1.0, (s * s + b * b - a * a) / (2 * s * b))))
    kite = 0.5 * math.sqrt(max(0.0, (-s + a + b) * (s + a - b) * (s - a + b) * (s + a + b)))
    return min(1.0, max(0.0, (a * a * alpha + b * b * beta - kite) / (math.pi * a * a)))


def sky_beam(rate_mm_h: float, p_min: float, s: float, k: float, divergence: float = 0.003,
             r_ref: float = 10.0, r_max: float = 120.0) -> tuple[float, float]:
    """(chance that a sky beam holds a detectable flake, their median range in m)."""
    n0 = 2500 * rate_mm_h**-0.94 / FLAKE_PER_MELTED
    lam = 2.29 * rate_mm_h**-0.45 / FLAKE_PER_MELTED
    alpha = 2 * AREA_COEFFICIENT_MM2 * n0 * math.gamma(AREA_EXPONENT + 1) / lam ** (AREA_EXPONENT + 1) * 1e-6
    ranges, cumulative, total = [], [], 0.0
    r = 0.95
    while r < r_max:
        full = REFLECTANCE * (r_ref / r) ** 2 * overlap(r, divergence, s, k) * math.exp(-2 * alpha * r)
        if full >= p_min and full > 0:
            beam_mm2 = math.pi / 4 * ((APERTURE_M + divergence * r) * 1e3) ** 2
            d_min = (beam_mm2 * p_min / full / AREA_COEFFICIENT_MM2) ** (1 / AREA_EXPONENT)
            if d_min < D_MAX_MM:
                count = n0 / lam * (math.exp(-lam * d_min) - math.exp(-lam * D_MAX_MM))
                total += math.pi / 4 * (APERTURE_M + divergence * r) ** 2 * count * 0.1
        ranges.append(r)
        cumulative.append(total)
        r += 0.1
    if total == 0:
        return 0.0, float("nan")
    median = ranges[bisect.bisect_left(cumulative, 0.5 * total)]
    return 1 - math.exp(-total), median


def main() -> None:
    gate, datasheet = 0.1 * (10 / 120) ** 2, 0.1 * (10 / 40) ** 2
    for name, p_min in (("range-gate threshold", gate), ("OS1 datasheet threshold", datasheet)):
        for rate in (1.0, 3.0):
            share, median = sky_beam(rate, p_min, 0.026, 1.5)
            print(f"{name}, s 26 mm, k 1.5, {rate:g} mm/h: {100 * share:.4f} %, median {median:.2f} m")
    fits = []
    for s in (0.011, 0.014, 0.017, 0.020, 0.022, 0.024, 0.026, 0.030, 0.035):
        for k in (1.5, 2, 3, 4, 5, 6, 8):
            (a, ma), (b, mb) = sky_beam(1.0, datasheet, s, k), sky_beam(3.0, datasheet, s, k)
            if 0.02 <= a <= 0.15 and 0.02 <= b <= 0.15:
                fits.append((ma, s, k, a, b, mb))
    for ma, s, k, a, b, mb in sorted(fits, reverse=True)[:5]:
        print(f"OS1 datasheet, s {1e3 * s:.0f} mm, k {k:g}: {100 * a:.1f} % / {100 * b:.1f} %, "
              f"median {ma:.2f} / {mb:.2f} m")


if __name__ == "__main__":
    main()
