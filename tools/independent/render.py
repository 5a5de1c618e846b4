#!/usr/bin/env python3
"""Independent renderer for bouncelab test sessions (written from first principles;
does not use bouncelab's crates/render or its model code).

Conventions (see README.md next to this file):
  * Surface frame: x along the surface pointing down-slope, y along the outward normal,
    origin at the point of first touch projected onto the surface plane (y = 0 is the plane).
    The ball centre is at height y; contact while y < R; penetration delta = R - y.
  * Camera levelled with the incline (as in the paper): the surface is horizontal in the image,
    gravity is tilted: g_x = +g sin(beta) (down-slope), g_y = -g cos(beta).
    Image: x_px = x0_px + x/s (down-slope = +x_px, session downslope = "+x"),
           y_px = line_y_px - y/s   (pixel centres at integer coordinates, y down).
  * Ball: diameter 0.067 m, mass 0.0567 kg, moment of inertia I = 2/3 m R^2 (thin shell).
  * Spin omega: counter-clockwise (in the x-right / y-up surface frame, = counter-clockwise as
    seen in the image); contact-point slip = v_t + omega R.
  * mu_eff = -(v_t,out - v_t,in) / (v_n,out - v_n,in)   (bouncelab outputs.md definition, signed;
    the paper's ratio of momentum changes with its sign convention).
  * Normal contact ('linear' model): P = k delta + b d(delta)/dt during compression (d delta/dt > 0),
    P = k delta during restitution, P >= 0 (the paper's hybrid elastic / viscoelastic model).
    'hertz' model: P = k_h delta^1.5 + b d(delta)/dt in compression, k_h delta^1.5 in restitution.
  * Tangential: Coulomb friction |F| <= mu P on the contact point's slip with stick/slip.
  * Optional quadratic air drag in flight (and contact) F = -1/2 rho Cd pi R^2 |v| v.
  * Time: frame i at t = i / fps; the exposure (50 us) is centred on that instant and motion blur
    is the mean of NSUB sub-frame renders spread over the exposure.
  * Contact drawing: the ball is drawn as an undeformed circle at its true centre; the surface band
    (whose top edge is the plane y = 0, ragged for clay) is composited in front of it, so the part of
    the ball that has penetrated below the band's top edge is hidden.
"""
import argparse, csv, json, math, os, sys, time
import numpy as np
from PIL import Image
from scipy import ndimage

G = 9.81
D_BALL = 0.067
R_BALL = D_BALL / 2
M_BALL = 0.0567
I_FACTOR = 2.0 / 3.0
FPS = 10000.0

# ----------------------------------------------------------------------------------------------
# physics


def contact_force(model, p, delta, ddelta):
    if delta <= 0.0:
        return 0.0
    if model == "hertz":
        el = p["k_h"] * delta ** 1.5
    else:
        el = p["k"] * delta
    f = el + (p["b"] * ddelta if ddelta > 0 else 0.0)
    return max(f, 0.0)


def simulate(p, beta_deg, h, drag_cd=0.0, rho=1.204):
    """Drop from rest, centre falling h (vertically) to the touch position if there were no drag.
    Returns dict with dense trajectory (t relative to touch) and truth quantities."""
    beta = math.radians(beta_deg)
    gx, gy = G * math.sin(beta), -G * math.cos(beta)
    m, R = M_BALL, R_BALL
    I = I_FACTOR * m * R * R
    kd = 0.5 * rho * drag_cd * math.pi * R * R / m  # drag accel = -kd |v| v
    model = p["model"]
    mu = p["mu"]
    meff = 1.0 / (1.0 / m + R * R / I)

    # state: x, y, vx, vy, theta, omega
    # release point: vertical distance h above the touch point (centre at y = R at touch, x = 0)
    # vertical unit (up) in surface frame: (-sin b, cos b)
    s0 = np.array([-h * math.sin(beta), R + h * math.cos(beta), 0.0, 0.0, 0.0, 0.0])

    def deriv(s, mode):
        x, y, vx, vy, th, om = s
        ax, ay, al = gx, gy, 0.0
        if kd > 0:
            sp = math.hypot(vx, vy)
            ax -= kd * sp * vx
            ay -= kd * sp * vy
        delta = R - y
        if delta > 0:
            P = contact_force(model, p, delta, -vy)
            ay += P / m
            if mode == 0:  # stick
                Freq = -meff * (ax)  # keeps slip rate zero (tangential accel other than friction = ax)
                F = max(-mu * P, min(mu * P, Freq))
            else:
                F = -mu * P * mode
            ax += F / m
            al = R * F / I
        return np.array([vx, vy, ax, ay, om, al])

    def rk4(s, dt, mode):
        k1 = deriv(s, mode)
        k2 = deriv(s + 0.5 * dt * k1, mode)
        k3 = deriv(s + 0.5 * dt * k2, mode)
        k4 = deriv(s + dt * k3, mode)
        return s + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)

    # --- flight to touch: coarse steps far away, fine near the surface
    t = 0.0
    s = s0.copy()
    traj_t, traj_s = [], []
    if kd == 0:
        # analytic: jump to 2 ms before touch
        v_imp = math.sqrt(2 * G * h)
        tt = v_imp / G  # time to fall h
        t = tt - 0.003
        vx, vy = gx * t, gy * t
        s = np.array([s0[0] + 0.5 * gx * t * t, s0[1] + 0.5 * gy * t * t, vx, vy, 0.0, 0.0])
    else:
        while True:
            traj_t.append(t)
            traj_s.append(s.copy())
            sn = rk4(s, 2e-5, 1)
            if sn[1] - R < 0.02:
                break
            s, t = sn, t + 2e-5
    dt = 1e-6
    mode = 1
    touched = None
    left = None
    while True:
        traj_t.append(t)
        traj_s.append(s.copy())
        delta = R - s[1]
        slip = s[2] + s[5] * R
        if delta > 0:
            if mode != 0:
                mode = 1 if slip > 0 else -1
                if abs(slip) < 1e-9:
                    mode = 0
        else:
            mode = 1 if slip >= 0 else -1
        sn = rk4(s, dt, mode)
        # stick -> slip check
        if R - sn[1] > 0:
            if mode == 0:
                P = contact_force(model, p, R - sn[1], -sn[3])
                ax = gx - (kd * math.hypot(sn[2], sn[3]) * sn[2] if kd > 0 else 0.0)
                if abs(meff * ax) > mu * P:
                    mode = 1 if (-meff * ax) < 0 else -1  # friction saturates; slides
            else:
                slipn = sn[2] + sn[5] * R
                if slipn * mode <= 0:  # slip crossed zero within the step: apply the stopping impulse
                    J = -slipn * meff
                    sn[2] += J / m
                    sn[5] += R * J / I
                    mode = 0
        # events
        if touched is None and s[1] >= R > sn[1]:
            f = (s[1] - R) / (s[1] - sn[1])
            touched = (t + f * dt, s + f * (sn - s))
        if touched is not None and left is None and s[1] < R <= sn[1] and (t - touched[0]) > 1e-4:
            f = (R - s[1]) / (sn[1] - s[1])
            left = (t + f * dt, s + f * (sn - s))
        s, t = sn, t + dt
        if left is not None and t > left[0] + 0.030:
            break
        if touched is not None and left is None and t - touched[0] > 0.05:
            raise RuntimeError("no separation")
    T = np.array(traj_t)
    S = np.array(traj_s)
    t0 = touched[0]
    T = T - t0
    sin_, sout = touched[1], left[1]
    # trajectory before the fine part: for no-drag analytic extension backwards
    ymask = (T >= 0) & (T <= left[0] - t0)
    dmax = float(np.max(R - S[ymask, 1])) if ymask.any() else 0.0
    res = dict(
        T=T, S=S, t_leave=left[0] - t0, x_touch=sin_[0],
        v_in_t=sin_[2], v_in_n=sin_[3], v_out_t=sout[2], v_out_n=sout[3],
        spin_in=sin_[5], spin_out=sout[5], delta_max=dmax,
        analytic_back=(kd == 0), gx=gx, gy=gy, kd=kd,
    )
    res["cor"] = -res["v_out_n"] / res["v_in_n"]
    res["mu_eff"] = -(res["v_out_t"] - res["v_in_t"]) / (res["v_out_n"] - res["v_in_n"])
    res["contact_ms"] = res["t_leave"] * 1e3
    # re-centre x on the touch point
    res["S"][:, 0] -= sin_[0]
    return res


def positions(res, tq):
    """centre (x, y, theta) at times tq (relative to touch)."""
    T, S = res["T"], res["S"]
    tq = np.asarray(tq, float)
    x = np.interp(tq, T, S[:, 0])
    y = np.interp(tq, T, S[:, 1])
    th = np.interp(tq, T, S[:, 4])
    lo = tq < T[0]
    if lo.any():
        if not res["analytic_back"]:
            raise RuntimeError("query before trajectory start")
        dt = tq[lo] - T[0]
        s = S[0]
        x[lo] = s[0] + s[2] * dt + 0.5 * res["gx"] * dt * dt
        y[lo] = s[1] + s[3] * dt + 0.5 * res["gy"] * dt * dt
        th[lo] = s[4]
    if (tq > T[-1]).any():
        raise RuntimeError("query after trajectory end")
    return x, y, th

# ----------------------------------------------------------------------------------------------
# looks


def smooth_noise(rng, shape, sigma):
    n = rng.standard_normal(shape)
    n = ndimage.gaussian_filter(n, sigma, mode="wrap")
    return n / (n.std() + 1e-12)


def seam_curve(rng, npts=720):
    b = rng.uniform(0.27, 0.33)
    a = 1 - b
    t = np.linspace(0, 2 * np.pi, npts, endpoint=False)
    P = np.stack([a * np.cos(t) + b * np.cos(3 * t), a * np.sin(t) - b * np.sin(3 * t),
                  2 * math.sqrt(a * b) * np.sin(2 * t)], 1)
    # random rotation
    q = rng.standard_normal(4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    Rm = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                   [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                   [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    return P @ Rm.T


def make_ball_texture(rng, N=384):
    """Albedo of the visible hemisphere in body coordinates on [-1.06, 1.06]^2 (N x N).
    Spin is about the camera axis, so the visible hemisphere is always the same part of the body."""
    ext = 1.06
    u = np.linspace(-ext, ext, N)
    U, V = np.meshgrid(u, u)
    r2 = U * U + V * V
    Z = np.sqrt(np.clip(1 - r2, 0, 1))
    # felt: fine fibres + blotches
    fib = smooth_noise(rng, (N, N), 0.8)
    blot = smooth_noise(rng, (N, N), 10.0)
    felt = 0.78 + rng.uniform(0.03, 0.06) * fib + rng.uniform(0.02, 0.05) * blot
    # seam: distance (chord) from the seam curve
    C = seam_curve(rng)
    pts = np.stack([U.ravel(), V.ravel(), Z.ravel()], 1)
    dmin = np.full(pts.shape[0], 9.0)
    for i in range(0, C.shape[0], 60):
        d = np.sqrt(((pts[:, None, :] - C[None, i:i + 60, :]) ** 2).sum(-1)).min(1)
        dmin = np.minimum(dmin, d)
    dmin = dmin.reshape(N, N)
    w = rng.uniform(0.035, 0.05)
    seam = np.exp(-0.5 * (dmin / w) ** 2)
    groove = np.exp(-0.5 * ((dmin - 1.6 * w) / (0.5 * w)) ** 2)
    seam_bright = rng.uniform(0.12, 0.22)
    alb = felt + seam_bright * seam - 0.10 * groove
    # rim fuzz: radial noise as a function of body angle
    return dict(alb=alb.astype(np.float32), ext=ext, N=N,
                fuzz=smooth_noise(rng, (720,), 1.5) * rng.uniform(0.004, 0.008))


def bilinear(img, ext, N, bu, bv):
    fx = (bu + ext) / (2 * ext) * (N - 1)
    fy = (bv + ext) / (2 * ext) * (N - 1)
    fx = np.clip(fx, 0, N - 1.001)
    fy = np.clip(fy, 0, N - 1.001)
    x0 = fx.astype(np.int32)
    y0 = fy.astype(np.int32)
    ax = fx - x0
    ay = fy - y0
    return ((img[y0, x0] * (1 - ax) + img[y0, x0 + 1] * ax) * (1 - ay)
            + (img[y0 + 1, x0] * (1 - ax) + img[y0 + 1, x0 + 1] * ax) * ay)


def render_ball(tex, look, cx, cy, rpx, theta, box):
    """Return (value, alpha) arrays over box=(y0,y1,x0,x1) for a ball centred at (cx, cy) px."""
    y0, y1, x0, x1 = box
    yy, xx = np.mgrid[y0:y1, x0:x1].astype(np.float32)
    u = (xx - cx) / rpx
    v = (yy - cy) / rpx
    c, s = math.cos(theta), math.sin(theta)
    bu = u * c - v * s
    bv = u * s + v * c
    r = np.sqrt(u * u + v * v)
    # fuzzy rim (noise rotates with the body)
    ang = np.arctan2(bv, bu)
    fz = (ang + np.pi) / (2 * np.pi) * 720
    i0 = np.floor(fz).astype(np.int32)
    w1 = fz - i0
    fuzz = tex["fuzz"]
    redge = 1.0 + fuzz[i0 % 720] * (1 - w1) + fuzz[(i0 + 1) % 720] * w1  # continuous rim
    soft = look["rim_soft_px"] / rpx
    alpha = np.clip((redge - r) / soft + 0.5, 0, 1)
    alb = bilinear(tex["alb"], tex["ext"], tex["N"], bu, bv)
    Z = np.sqrt(np.clip(1 - r * r, 0, 1))
    lx, ly, lz = look["light"]
    lam = np.clip(u * lx + v * ly + Z * lz, 0, None)
    shade = look["ambient"] + (1 - look["ambient"]) * lam
    sheen = look["sheen"] * (1 - np.clip(Z, 0, 1)) ** 3
    val = look["ball_level"] * (alb * shade + sheen)
    return val, alpha


def make_scene(rng, look, W=512, H=512):
    yy, xx = np.mgrid[0:H, 0:W].astype(np.float64)
    # backdrop with lighting gradient
    bg = look["bg_level"] * (1 + look["grad_x"] * (xx - W / 2) / W + look["grad_y"] * (yy - H / 2) / H)
    bg += look["bg_level"] * 0.03 * smooth_noise(rng, (H, W), 40)
    # band
    line = look["line_y"]
    if look["surface_kind"] == "clay":
        rough = smooth_noise(rng, (W,), rng.uniform(1.5, 3.0)) * look["edge_rough_px"]
        rough -= rough.mean()
        edge = line + rough
        alpha = np.clip(yy - edge[None, :] + 0.5, 0, 1)
        # grains (speckle) inside the band and a few straddling the edge
        spk = rng.standard_normal((H, W))
        spk = ndimage.gaussian_filter(spk, 0.7)
        spk /= spk.std()
        coarse = smooth_noise(rng, (H, W), 3.0)
        band = look["band_level"] * (1 + 0.07 * spk + 0.04 * coarse)
        # lit lip: slight brightening just below the edge (or darkening)
        depth = yy - edge[None, :]
        band *= 1 + look["lip"] * np.exp(-np.clip(depth, 0, None) / 2.0)
        # grains on the edge (occluding, drawn as part of the band)
        ng = int(rng.integers(30, 70))
        for _ in range(ng):
            gx = rng.uniform(0, W)
            gy = edge[int(gx) % W] + rng.uniform(-1.5, 1.0)
            gr = rng.uniform(0.8, 2.0)
            d = np.hypot(xx - gx, yy - gy)
            a = np.clip(gr - d + 0.5, 0, 1)
            alpha = np.maximum(alpha, a)
    else:
        edge = np.full(W, line)
        alpha = np.clip(yy - line + 0.5, 0, 1)
        weave = np.sin((xx + (yy - line)) * 2 * np.pi / look["weave_px"]) * np.sin((xx - (yy - line)) * 2 * np.pi / look["weave_px"])
        band = look["band_level"] * (1 + 0.025 * weave + 0.02 * smooth_noise(rng, (H, W), 1.0))
    # illumination field (applied to everything) and vignetting
    r2 = ((xx - W / 2) ** 2 + (yy - H / 2) ** 2) / (W / 2) ** 2
    illum = (1 - look["vignette"] * r2) * (1 + look["illum_x"] * (xx - W / 2) / W + look["illum_y"] * (yy - H / 2) / H)
    return dict(bg=bg, band=band, band_alpha=alpha, illum=illum, edge=edge)


def sensor(rng, sig8, look, bits16):
    """sig8: expected signal in 8-bit DN. Returns uint8 or uint16 (12-bit << 4) image."""
    gain = look["gain_e_per_dn"]
    scale = 16.0 if bits16 else 1.0
    S = np.clip(sig8, 0, None) * look.get("prnu_map", 1.0)
    shot = rng.standard_normal(S.shape) * np.sqrt(S / gain)
    read = rng.standard_normal(S.shape) * look["read_noise_dn"]
    img = (S + shot + read) * scale
    if bits16:
        q = np.clip(np.round(img), 0, 4095).astype(np.uint16) << 4
    else:
        q = np.clip(np.round(img), 0, 255).astype(np.uint8)
    return q

# ----------------------------------------------------------------------------------------------
# sessions

SURF = {
    # paper-like constants, k N/m, b N s/m (compression only), mu
    "linear": {
        "clay": dict(model="linear", k=25650.0, b=19.0, mu=0.55),
        "tape": dict(model="linear", k=31000.0, b=13.0, mu=0.75),
    },
    "hertz": {
        "clay": dict(model="hertz", k_h=4.2e5, b=19.0, mu=0.55),
        "tape": dict(model="hertz", k_h=5.2e5, b=13.0, mu=0.75),
    },
}


def shot_list():
    shots = []
    for surf in ("clay", "tape"):
        for ang in (0.0, 7.5, 15.0, 22.5):
            for h in (0.3, 0.7):
                shots.append((surf, ang, h))
    return shots


def make_look(rng, sess, surf, idx):
    heavy = sess == "B"
    look = {}
    look["bg_level"] = rng.uniform(70, 120)
    look["ball_level"] = rng.uniform(175, 215)
    if rng.uniform() < 0.25 and not heavy:
        # ball darker than the backdrop on some clips
        look["bg_level"] = rng.uniform(180, 210)
        look["ball_level"] = rng.uniform(120, 150)
    look["light"] = tuple(np.array([rng.uniform(-0.5, 0.5), rng.uniform(-0.7, -0.2), 0.8]) /
                          np.linalg.norm([0.5, 0.5, 0.8]))
    L = np.array(look["light"]); L /= np.linalg.norm(L); look["light"] = tuple(L)
    look["ambient"] = rng.uniform(0.35, 0.55)
    look["sheen"] = rng.uniform(0.0, 0.25)
    look["rim_soft_px"] = rng.uniform(1.0, 2.0)
    look["surface_kind"] = surf
    if surf == "clay":
        look["band_level"] = look["bg_level"] * rng.uniform(0.88, 1.12)
        look["edge_rough_px"] = rng.uniform(1.0, 2.5)
        look["lip"] = rng.uniform(-0.08, 0.12)
    else:
        look["band_level"] = rng.choice([rng.uniform(200, 235), rng.uniform(35, 55)])
        look["weave_px"] = rng.uniform(5, 9)
    look["line_y"] = float(rng.uniform(360, 430))
    look["scale"] = float(rng.uniform(0.00040, 0.00052))  # m/px -> R 64..84 px
    look["vignette"] = rng.uniform(0.05, 0.15)
    look["grad_x"] = rng.uniform(-0.1, 0.1)
    look["grad_y"] = rng.uniform(-0.1, 0.1)
    look["illum_x"] = rng.uniform(-0.1, 0.1)
    look["illum_y"] = rng.uniform(-0.1, 0.1)
    look["read_noise_dn"] = rng.uniform(2.0, 3.0)
    look["gain_e_per_dn"] = rng.uniform(15, 30)
    look["exposure_s"] = 50e-6
    look["nsub"] = 5
    look["bits16"] = False
    if heavy:
        look["read_noise_dn"] = rng.uniform(8.0, 10.0)
        look["gain_e_per_dn"] = rng.uniform(4, 8)
        look["vignette"] = rng.uniform(0.25, 0.4)
        look["grad_x"] = rng.choice([-1, 1]) * rng.uniform(0.3, 0.5)
        look["grad_y"] = rng.uniform(-0.3, 0.3)
        look["illum_x"] = rng.choice([-1, 1]) * rng.uniform(0.2, 0.35)
        look["illum_y"] = rng.uniform(-0.2, 0.2)
        look["bits16"] = bool(idx % 3 == 0)
        look["prnu"] = 0.01
    return look


def render_clip(rng, sess, idx, surf, ang, h, model_name, drag_cd, sess_dir, truth_dir, name, look_rng):
    p = SURF[model_name][surf]
    res = simulate(p, ang, h, drag_cd=drag_cd)
    look = make_look(look_rng, sess, surf, idx)
    s = look["scale"]
    rpx = R_BALL / s
    pre = float(rng.uniform(0.015, 0.020))
    post = float(rng.uniform(0.015, 0.020))
    t_start = -pre
    t_end = res["t_leave"] + post
    nfr = int(math.floor((t_end - t_start) * FPS)) + 1
    tf = t_start + np.arange(nfr) / FPS
    x, y, th = positions(res, tf)
    # horizontal placement: centre the path's x range in the frame
    xmin, xmax = x.min(), x.max()
    x0 = 256 - 0.5 * (xmin + xmax) / s + float(rng.uniform(-15, 15))
    line = look["line_y"]
    W = H = 512
    scene = make_scene(look_rng, look, W, H)
    if look.get("prnu"):
        look["prnu_map"] = 1 + look["prnu"] * look_rng.standard_normal((H, W))
    tex = make_ball_texture(look_rng)
    cdir = os.path.join(sess_dir, name)
    os.makedirs(cdir, exist_ok=True)
    bg_lit = scene["bg"]
    rows = []
    nsub = look["nsub"]
    offs = (np.arange(nsub) + 0.5) / nsub - 0.5
    for i in range(nfr):
        ts = tf[i] + offs * look["exposure_s"]
        xs, ys, ths = positions(res, ts)
        cxs = x0 + xs / s
        cys = line - ys / s
        comp = bg_lit.copy()
        # bounding box
        bx0 = int(max(0, math.floor(cxs.min() - rpx * 1.1 - 3)))
        bx1 = int(min(W, math.ceil(cxs.max() + rpx * 1.1 + 3)))
        by0 = int(max(0, math.floor(cys.min() - rpx * 1.1 - 3)))
        by1 = int(min(H, math.ceil(cys.max() + rpx * 1.1 + 3)))
        if bx1 > bx0 and by1 > by0:
            acc = np.zeros((by1 - by0, bx1 - bx0))
            for k in range(nsub):
                val, a = render_ball(tex, look, cxs[k], cys[k], rpx, ths[k], (by0, by1, bx0, bx1))
                sub = bg_lit[by0:by1, bx0:bx1]
                acc += sub * (1 - a) + val * a
            comp[by0:by1, bx0:bx1] = acc / nsub
        comp = comp * (1 - scene["band_alpha"]) + scene["band"] * scene["band_alpha"]
        sig = comp * scene["illum"]
        img = sensor(rng, sig, look, look["bits16"])
        fn = os.path.join(cdir, f"frame_{i:06d}.png")
        if look["bits16"]:
            Image.fromarray(img).save(fn, compress_level=1)
        else:
            Image.fromarray(img).save(fn, compress_level=1)
        cx, cy = x0 + x[i] / s, line - y[i] / s
        rows.append(dict(frame=i, t_s=i / FPS, t_rel_touch_s=tf[i], x_m=x[i], y_m=y[i],
                         x_px=cx, y_px=cy, theta_rad=th[i],
                         x_px_blurmean=float(cxs.mean()), y_px_blurmean=float(cys.mean()),
                         in_contact=int(y[i] < R_BALL)))
    os.makedirs(truth_dir, exist_ok=True)
    with open(os.path.join(truth_dir, f"{name}_frames.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    truth = dict(clip=name, surface=surf, angle_deg=ang, drop_height_m=h, model=model_name,
                 drag_cd=drag_cd, params={k: v for k, v in p.items()},
                 v_in_t_m_s=res["v_in_t"], v_in_n_m_s=res["v_in_n"],
                 v_out_t_m_s=res["v_out_t"], v_out_n_m_s=res["v_out_n"],
                 impact_speed_m_s=math.hypot(res["v_in_t"], res["v_in_n"]),
                 cor=res["cor"], mu_eff=res["mu_eff"], contact_ms=res["contact_ms"],
                 delta_max_mm=res["delta_max"] * 1e3, spin_in_rad_s=res["spin_in"],
                 spin_out_rad_s=res["spin_out"], t_touch_s=pre, t_sep_s=pre + res["t_leave"],
                 frames=nfr, scale_m_per_px=s, r_px=rpx, line_y_px=line, x0_px=x0,
                 look={k: (v if not isinstance(v, np.ndarray) else "map") for k, v in look.items()
                       if k != "prnu_map"})
    return truth


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--session", required=True, choices=["A", "B", "C", "D"])
    ap.add_argument("--out", required=True, help="session folder")
    ap.add_argument("--truth", required=True, help="truth folder (outside the session)")
    ap.add_argument("--seed", type=int, default=20240628)
    ap.add_argument("--only", type=int, default=None, help="render only clip index N (debug)")
    a = ap.parse_args()
    sess = a.session
    model_name = "hertz" if sess == "C" else "linear"
    drag_cd = 0.55 if sess == "D" else 0.0
    # physics seed is shared by A, B, C, D (same timing); looks seed per session (B differs)
    os.makedirs(a.out, exist_ok=True)
    os.makedirs(a.truth, exist_ok=True)
    shots = shot_list()
    truths = []
    looks_seed = {"A": 1, "B": 2, "C": 1, "D": 1}[sess]
    t0 = time.time()
    for idx, (surf, ang, h) in enumerate(shots):
        if a.only is not None and idx != a.only:
            continue
        name = f"{surf}_{ang:g}deg_{int(round(h * 1000))}mm"
        rng = np.random.default_rng([a.seed, 100 + idx])  # timing + sensor noise
        look_rng = np.random.default_rng([a.seed, looks_seed, idx])
        if sess == "B":
            rng = np.random.default_rng([a.seed, 100 + idx])
        tr = render_clip(rng, sess, idx, surf, ang, h, model_name, drag_cd, a.out, a.truth, name, look_rng)
        truths.append(tr)
        print(f"{name}: frames={tr['frames']} cor={tr['cor']:.4f} mu_eff={tr['mu_eff']:.4f} "
              f"contact={tr['contact_ms']:.3f}ms dmax={tr['delta_max_mm']:.2f}mm "
              f"r_px={tr['r_px']:.1f} 16bit={tr['look']['bits16']} ({time.time() - t0:.0f}s)", flush=True)
    with open(os.path.join(a.out, "session.toml"), "w") as f:
        f.write(f'[session]\ndescription = "independent renderer, session {sess}"\n\n'
                f"[ball]\ndiameter_m = {D_BALL}\nmass_kg = {M_BALL}\n\n"
                f'[camera]\nfps = 10000\ndownslope = "+x"\nexposure_s = 5e-5\n')
    with open(os.path.join(a.out, "clips.csv"), "w") as f:
        f.write("clip,surface,angle_deg,drop_height_m\n")
        for tr in truths:
            f.write(f"{tr['clip']},{tr['surface']},{tr['angle_deg']:g},{tr['drop_height_m']:g}\n")
    keys = ["clip", "surface", "angle_deg", "drop_height_m", "v_in_t_m_s", "v_in_n_m_s", "v_out_t_m_s",
            "v_out_n_m_s", "impact_speed_m_s", "cor", "mu_eff", "contact_ms", "delta_max_mm",
            "spin_in_rad_s", "spin_out_rad_s", "t_touch_s", "t_sep_s", "frames", "scale_m_per_px",
            "r_px", "line_y_px", "x0_px"]
    with open(os.path.join(a.truth, "truth.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(keys + ["bits16", "read_noise_dn"])
        for tr in truths:
            w.writerow([tr[k] for k in keys] + [tr["look"]["bits16"], tr["look"]["read_noise_dn"]])
    with open(os.path.join(a.truth, "truth.json"), "w") as f:
        json.dump(truths, f, indent=1, default=float)


if __name__ == "__main__":
    main()
