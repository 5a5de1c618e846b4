#!/usr/bin/env python3
"""Compare bouncelab analyze output (OUT/estimates.csv, OUT/trajectories) with the independent truth.
usage: compare.py TRUTH_DIR OUT_DIR"""
import csv, json, math, os, sys
import numpy as np

truth_dir, out_dir = sys.argv[1], sys.argv[2]
T = {r["clip"]: r for r in csv.DictReader(open(os.path.join(truth_dir, "truth.csv")))}
E = {r["clip"]: r for r in csv.DictReader(open(os.path.join(out_dir, "estimates.csv")))}

Q = [  # (name, estimate column, truth column, se column, scale)
    ("v_in_t", "v_in_t_m_s", "v_in_t_m_s", "v_in_t_se_m_s", 1),
    ("v_in_n", "v_in_n_m_s", "v_in_n_m_s", "v_in_n_se_m_s", 1),
    ("v_out_t", "v_out_t_m_s", "v_out_t_m_s", "v_out_t_se_m_s", 1),
    ("v_out_n", "v_out_n_m_s", "v_out_n_m_s", "v_out_n_se_m_s", 1),
    ("cor", "cor", "cor", "cor_se", 1),
    ("mu_eff", "mu_eff", "mu_eff", "mu_eff_se", 1),
    ("contact_ms", "contact_ms", "contact_ms", "contact_se_ms", 1),
    ("dmax_mm", "delta_max_mm", "delta_max_mm", "delta_max_se_mm", 1),
    ("spin_out", "spin_out_rad_s", "spin_out_rad_s", "spin_out_se_rad_s", 1),
    ("t_touch_ms", "t_touch_s", "t_touch_s", "t_touch_se_s", 1e3),
    ("t_sep_ms", "t_sep_s", "t_sep_s", "t_sep_se_s", 1e3),
]


def f(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return float("nan")


rows = []
for clip, t in T.items():
    e = E.get(clip)
    row = dict(clip=clip, surface=t["surface"], measured=e is not None)
    if e is None:
        rows.append(row)
        continue
    for name, ec, tc, sc, k in Q:
        err = (f(e[ec]) - f(t[tc])) * k
        se = f(e[sc]) * k
        row[name] = err
        row[name + "_z"] = err / se if se > 0 else float("nan")
    row["flags"] = e["flags"]
    row["notes"] = e["notes"]
    row["line"] = e["contact_line"]
    row["tilt"] = f(e["surface_tilt_deg"])
    rows.append(row)

# per-shot table
cols = ["v_in_n", "v_out_n", "v_in_t", "v_out_t", "cor", "mu_eff", "contact_ms", "dmax_mm", "t_touch_ms", "t_sep_ms", "spin_out"]
print("per-shot errors (bouncelab - truth); z = error / bouncelab's SE")
hdr = f"{'clip':22s} {'line':10s} " + " ".join(f"{c:>9s}" for c in cols) + "  z(cor) z(mu) z(tc)"
print(hdr)
for r in rows:
    if not r["measured"]:
        print(f"{r['clip']:22s} NOT MEASURED")
        continue
    print(f"{r['clip']:22s} {r['line']:10s} " + " ".join(f"{r[c]:+9.4f}" for c in cols)
          + f"  {r['cor_z']:+5.1f} {r['mu_eff_z']:+5.1f} {r['contact_ms_z']:+5.1f}")
print()
print("summary per surface: RMS / worst |error| (n measured)")
for surf in sorted(set(r["surface"] for r in rows)):
    rs = [r for r in rows if r["surface"] == surf and r["measured"] and not r.get("flags")]
    line = f"{surf:6s} n={len(rs):2d} "
    for c in ["cor", "mu_eff", "v_in_n", "v_out_n", "v_in_t", "v_out_t", "contact_ms", "dmax_mm", "spin_out"]:
        a = np.array([r[c] for r in rs if not math.isnan(r[c])])
        if len(a):
            line += f"| {c} {np.sqrt(np.mean(a**2)):.4f}/{np.max(np.abs(a)):.4f} mean {np.mean(a):+.4f} "
    print(line)
    zs = [c for c in ["cor", "mu_eff", "contact_ms"]]
    print("       RMS z: " + " ".join(f"{c} {np.sqrt(np.nanmean(np.array([r[c+'_z'] for r in rs])**2)):.2f}" for c in zs))
print()
print("flags / notes:")
for r in rows:
    if not r["measured"]:
        continue
    if r.get("flags") or r.get("notes"):
        print(f"  {r['clip']}: flags=[{r['flags']}] notes=[{r['notes']}]")

# centre tracking from OUT/trajectories
print()
print("centre error vs truth (px): flight RMS / contact RMS / contact mean (dx,dy) - flight mean; statuses")
for clip, t in T.items():
    e = E.get(clip)
    fn = os.path.join(out_dir, e["trajectory_file"]) if e else os.path.join(out_dir, "trajectories", clip + ".csv")
    if not os.path.exists(fn):
        continue
    tr = {int(r["frame"]): r for r in csv.DictReader(open(os.path.join(truth_dir, clip + "_frames.csv")))}
    # Matched by time, so that a copy keeping every Nth frame (`perturb.py --every N`) meets its truth.
    truth_dt = f(tr[1]["t_s"]) - f(tr[0]["t_s"]) if 0 in tr and 1 in tr else float("nan")
    fl, co, st = [], [], {}
    for r in csv.DictReader(open(fn)):
        st[r["status"]] = st.get(r["status"], 0) + 1
        if r["status"] not in ("ok", "occluded") or r["x_px"] == "":
            continue
        k = int(round(f(r["t_s"]) / truth_dt)) if truth_dt > 0 and r.get("t_s") else int(r["frame"])
        if k not in tr:
            continue
        g = tr[k]
        d = (f(r["x_px"]) - f(g["x_px"]), f(r["y_px"]) - f(g["y_px"]))
        (co if int(g["in_contact"]) else fl).append(d)
    fl, co = np.array(fl), np.array(co)
    frms = np.sqrt(np.mean(np.sum(fl ** 2, 1))) if len(fl) else float("nan")
    crms = np.sqrt(np.mean(np.sum(co ** 2, 1))) if len(co) else float("nan")
    fm = fl.mean(0) if len(fl) else np.array([np.nan, np.nan])
    cm = co.mean(0) if len(co) else np.array([np.nan, np.nan])
    print(f"  {clip:22s} flight {frms:.3f} (mean {fm[0]:+.3f},{fm[1]:+.3f})  contact {crms:.3f} "
          f"shift ({cm[0]-fm[0]:+.3f},{cm[1]-fm[1]:+.3f})  {st}")

# surface line and scale from the store
import sqlite3, glob
st = os.path.join(out_dir, "store.sqlite")
if os.path.exists(st):
    J = {t["clip"]: t for t in json.load(open(os.path.join(truth_dir, "truth.json")))}
    c = sqlite3.connect(st)
    print()
    print("surface line found - truth (px, + = below), tilt, scale error %, and the estimate's contact error")
    q = ("select s.clip, t.surface_y_px, t.surface_tilt_deg, t.scale_m_per_px, t.warnings from shots s "
         "join tracks t on t.shot_id = s.id")
    for clip, ypx, tilt, sc, warn in c.execute(q):
        if clip not in J:
            continue
        tj = J[clip]
        r = next((r for r in rows if r["clip"] == clip), None)
        dl = (ypx - tj["line_y_px"]) if ypx is not None else float("nan")
        print(f"  {clip:22s} line {dl:+7.2f} px  tilt {tilt if tilt is not None else float('nan'):+.3f}  "
              f"scale {100 * (sc / tj['scale_m_per_px'] - 1) if sc else float('nan'):+.3f} %  "
              f"contact err {r.get('contact_ms', float('nan')) if r else float('nan'):+.3f} ms  "
              f"line used {r.get('line', '') if r else ''}  warnings {warn if warn != '[]' else ''}")
