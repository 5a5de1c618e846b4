#!/usr/bin/env python3
"""Each shot's flight scatter, in pixels and in ball radii, from `bouncelab analyze` outputs.

    python3 tools/flight_scatter.py OUT [OUT ...] [--top N] [--radius]

For every shot in OUT/estimates.csv with a touch and a separation time (and a flight of six frames or
more), the `ok` frames of its trajectory
more than 0.3 ms before the touch and after the separation are fitted by a quadratic in time per
coordinate; the root-mean-square distance of the centres from that arc is printed per flight, with the
worse flight over the ball's median radius. The shots of each folder come worst first (the first N with
--top). This is the measure behind the estimator's `FLIGHT_SCATTER_MAX_RADII` (docs/accuracy.md), computed
independently of it. With --radius, the measured radius's RMS about a straight line in time instead (n - 2
degrees of freedom), the measure behind `RIM_WANDER_MAX_RADII`. Needs numpy.
"""
import argparse
import csv
import os

import numpy as np


def flight_rms_px(frames):
    if len(frames) < 6:
        return float("nan")
    t = np.array([float(f["t_s"]) for f in frames])
    t -= t.mean()
    sq = 0.0
    for key in ("x_px", "y_px"):
        v = np.array([float(f[key]) for f in frames])
        sq = sq + (v - np.polyval(np.polyfit(t, v, 2), t)) ** 2
    return float(np.sqrt(np.mean(sq)))


def radius_rms_px(frames):
    if len(frames) < 6:
        return float("nan")
    t = np.array([float(f["t_s"]) for f in frames])
    t -= t.mean()
    r = np.array([float(f["r_px"]) for f in frames])
    res = r - np.polyval(np.polyfit(t, r, 1), t)
    return float(np.sqrt(np.sum(res**2) / (len(r) - 2)))


def shots(out, measure=flight_rms_px):
    with open(os.path.join(out, "estimates.csv")) as f:
        rows = list(csv.DictReader(f))
    for e in rows:
        if not e["t_touch_s"] or not e["t_sep_s"]:
            continue
        touch, sep = float(e["t_touch_s"]), float(e["t_sep_s"])
        with open(os.path.join(out, e["trajectory_file"])) as f:
            ok = [r for r in csv.DictReader(f) if r["status"] == "ok"]
        flights = (
            [r for r in ok if float(r["t_s"]) < touch - 3e-4],
            [r for r in ok if float(r["t_s"]) > sep + 3e-4],
        )
        rms = [measure(fl) for fl in flights]
        if all(np.isnan(rms)):
            continue  # neither flight has the six frames a quadratic needs
        radius = float(np.median([float(r["r_px"]) for r in ok]))
        yield float(np.nanmax(rms)) / radius, e["clip"], rms, radius, bool(e["flags"])


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", nargs="+")
    p.add_argument("--top", type=int, default=0)
    p.add_argument("--radius", action="store_true", help="the radius's scatter about a line in time")
    a = p.parse_args()
    for out in a.out:
        ranked = sorted(shots(out, radius_rms_px if a.radius else flight_rms_px), reverse=True)
        for ratio, clip, rms, radius, flagged in ranked[: a.top or None]:
            mark = "\tflagged" if flagged else ""
            print(
                f"{out}\t{clip}\tin {rms[0]:.3f} px\tout {rms[1]:.3f} px\tradius {radius:.1f} px"
                f"\tworst {ratio:.4f} r{mark}"
            )


if __name__ == "__main__":
    main()
