"""An experiment, not pdeshape code: a fill of the unit disc by the polyharmonic equation Δ³X = 0
in the disc's own Cartesian coordinates, against the fill's periodic strip operator, on holes of
known surfaces with exact G2 data (no mesh, no collar).

Why: on a quadratic height field, `fill-holes` lies 2.0e-3 from the true surface where CGAL's
bi-Laplacian fairing lies 7.3e-4 (BENCHMARKS.md). The fill solves (∂²_u + a²∂²_v)³X = 0 on a
strip u ∈ [0, 1] closed in a pole; mode n of its solutions are e^{±nau}·(1, u, u²), while the
true surface's mode n, written in r = 1 − u, is a polynomial in r. In the disc, Δ³ is regular at
the centre and mode n of its regular solutions is r^n, r^{n+2}, r^{n+4}: every polynomial of
degree ≤ 5 in the disc's coordinates is one, so a quadratic height field over an ellipse,
parametrised by the ellipse's affine angle, is reproduced exactly. Per Fourier mode the three
coefficients solve a 3 × 3 system with rows (1, 1, 1), (n, n+2, n+4), (n(n−1), (n+2)(n+1),
(n+4)(n+3)) — a Vandermonde matrix in the exponents after row operations, determinant 16 for
every n.

Data at r = 1: X the loop; X_r the tangent vector whose projection on the loop's mean plane is
the projection of X − C (C the loop's centre): exactly the affine map's radial derivative;
X_rr = d·II(X_r, X_r)/(N·d) along the plane's normal d (G2: its normal part is the surface's
normal curvature; its tangential part is free). Optional: X_r scaled by f and μ·X_r added to
X_rr (G2 unchanged), searched on a grid; `--select` also prints, on a coarser grid, the
distance of the member that each of three energies chooses without the true surface: the
Willmore energy ∫H² dA (the mesh fills' rule today), the thin-plate energy ∫|ΔX|² and the
triharmonic energy ∫|∇ΔX|² (whose Euler–Lagrange equation is Δ³X = 0), all in the disc.

    python crates/pdeshape-io/bench/disk_fill_experiment.py [--select]   # numpy; minutes
"""

import sys

import numpy as np

N = 128
TH = 2 * np.pi * np.arange(N) / N
RR, TT = np.meshgrid(np.linspace(0, 1, 81), np.linspace(0, 2 * np.pi, 241), indexing="ij")


def solve(data):
    """Per component and mode n, the coefficients of r^n, r^{n+2}, r^{n+4} meeting X, X_r, X_rr."""
    out = []
    for comp in range(3):
        cf = [np.fft.rfft(d[:, comp]) / N for d in data]
        modes = []
        for n in range(N // 2):
            e = np.array([n, n + 2, n + 4], float)
            modes.append(np.linalg.solve(np.array([np.ones(3), e, e * (e - 1)]), np.array([c[n] for c in cf])))
        out.append(modes)
    return out


def evaluate(sol, r, t):
    res = np.zeros(r.shape + (3,))
    for comp in range(3):
        acc = np.zeros(r.shape, complex)
        for n, a in enumerate(sol[comp]):
            acc += (1 if n == 0 else 2) * (a[0] * r**n + a[1] * r ** (n + 2) + a[2] * r ** (n + 4)) * np.exp(1j * n * t)
        res[..., comp] = acc.real
    return res


def disc_fill(x, normal, second, centre, d, f=1.0, mu=0.0):
    g = (x - centre) - np.outer((x - centre) @ d, d)
    xr = f * (g + np.outer(-np.einsum("ij,ij->i", normal, g) / (normal @ d), d))
    xrr = np.outer(second(xr) / (normal @ d), d) + mu * xr
    return solve((x, xr, xrr))


def height_field(a, b, arc_length, f=1.0, mu=0.0, solution=False):
    q = lambda x, y: 0.3 * (x * x - 0.5 * y * y) + 0.1 * x * y  # noqa: E731
    t = TH
    if arc_length:
        tf = np.linspace(0, 2 * np.pi, 20001)
        s = np.concatenate([[0], np.cumsum(np.hypot(np.diff(a * np.cos(tf)), np.diff(b * np.sin(tf))))])
        t = np.interp(TH / (2 * np.pi) * s[-1], s, tf)
    x, y = a * np.cos(t), b * np.sin(t)
    gx, gy = 0.6 * x + 0.1 * y, -0.3 * y + 0.1 * x
    nrm = np.column_stack([-gx, -gy, np.ones_like(x)])
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    second = lambda v: (0.6 * v[:, 0] ** 2 + 0.2 * v[:, 0] * v[:, 1] - 0.3 * v[:, 1] ** 2) * nrm[:, 2]  # noqa: E731
    sol = disc_fill(np.column_stack([x, y, q(x, y)]), nrm, second, np.zeros(3), np.array([0, 0, 1.0]), f, mu)

    def dist(s):
        y3 = evaluate(s, RR, TT)
        return np.abs(y3[..., 2] - q(y3[..., 0], y3[..., 1])).max()

    return (sol, dist) if solution else dist(sol)


def sphere_cap(alpha, f=1.0, mu=0.0, solution=False):
    ca, sa = np.cos(alpha), np.sin(alpha)
    x = np.column_stack([sa * np.cos(TH), sa * np.sin(TH), np.full(N, ca)])
    second = lambda v: -np.einsum("ij,ij->i", v, v)  # noqa: E731
    sol = disc_fill(x, x, second, np.array([0, 0, ca]), np.array([0, 0, 1.0]), f, mu)
    dist = lambda s: np.abs(np.linalg.norm(evaluate(s, RR, TT), axis=-1) - 1).max()  # noqa: E731
    return (sol, dist) if solution else dist(sol)


def torus_hole(u0, w0, rad, f=1.0, mu=0.0, solution=False, big_r=1.0, r=0.4):
    """The torus (R = 1, r = 0.4) without the ball of radius `rad` at its point (u0, w0), as
    `cgal_mesh_holes.py` cuts it; the loop parametrised by the affine angle of a fitted ellipse."""
    pt = lambda u, w: np.stack([(big_r + r * np.cos(w)) * np.cos(u), (big_r + r * np.cos(w)) * np.sin(u), r * np.sin(w)], -1)  # noqa: E731
    phi = np.linspace(0, 2 * np.pi, 4000, endpoint=False)
    du, dw = np.cos(phi) / (big_r + r * np.cos(w0)), np.sin(phi) / r
    lo, hi = np.zeros_like(phi), np.ones_like(phi)
    for _ in range(60):
        m = (lo + hi) / 2
        inside = np.linalg.norm(pt(u0 + m * du, w0 + m * dw) - pt(u0, w0), axis=-1) < rad
        lo, hi = np.where(inside, m, lo), np.where(inside, hi, m)
    uu, ww = u0 + lo * du, w0 + lo * dw
    xl = pt(uu, ww)
    nl = np.stack([np.cos(ww) * np.cos(uu), np.cos(ww) * np.sin(uu), np.sin(ww)], -1)
    d = nl.mean(0) / np.linalg.norm(nl.mean(0))
    pj = xl - np.outer(xl @ d, d)
    c = pj.mean(0)
    e1 = np.cross(d, [1, 0, 0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(d, e1)
    q2 = np.column_stack([(pj - c) @ e1, (pj - c) @ e2])
    k = np.linalg.lstsq(np.column_stack([q2[:, 0] ** 2, q2[:, 0] * q2[:, 1], q2[:, 1] ** 2]), np.ones(len(q2)), rcond=None)[0]
    wq, vq = np.linalg.eigh(np.array([[k[0], k[1] / 2], [k[1] / 2, k[2]]]))
    z = q2 @ (vq @ np.diag(np.sqrt(wq)) @ vq.T).T
    ang = np.unwrap(np.arctan2(z[:, 1], z[:, 0]))
    if ang[-1] < ang[0]:
        ang = -ang
    angw = np.concatenate([ang, [ang[0] + 2 * np.pi]])
    uq = np.interp(ang[0] + TH, angw, np.concatenate([uu, [uu[0]]]))
    wq_ = np.interp(ang[0] + TH, angw, np.concatenate([ww, [ww[0]]]))
    xu = np.stack([-(big_r + r * np.cos(wq_)) * np.sin(uq), (big_r + r * np.cos(wq_)) * np.cos(uq), 0 * uq], -1)
    xw = np.stack([-r * np.sin(wq_) * np.cos(uq), -r * np.sin(wq_) * np.sin(uq), r * np.cos(wq_)], -1)

    def second(v):
        a = np.einsum("ij,ij->i", v, xu) / np.einsum("ij,ij->i", xu, xu)
        b = np.einsum("ij,ij->i", v, xw) / np.einsum("ij,ij->i", xw, xw)
        return -(big_r + r * np.cos(wq_)) * np.cos(wq_) * a * a - r * b * b

    nq = np.stack([np.cos(wq_) * np.cos(uq), np.cos(wq_) * np.sin(uq), np.sin(wq_)], -1)
    sol = disc_fill(pt(uq, wq_), nq, second, c, d, f, mu)

    def dist(s):
        y3 = evaluate(s, RR, TT)
        return np.abs(np.hypot(np.hypot(y3[..., 0], y3[..., 1]) - big_r, y3[..., 2]) - r).max()

    return (sol, dist) if solution else dist(sol)


def energies(sol):
    """Triharmonic ∫|∇ΔX|², thin-plate ∫|ΔX|² and Willmore ∫H² dA of a disc fill, by
    Gauss–Legendre in r and the trapezoid rule in θ; derivatives of each mode exactly
    (Δ(r^m e^{inθ}) = (m² − n²) r^{m−2} e^{inθ})."""
    x, w = np.polynomial.legendre.leggauss(40)
    rq, wr, nt = (x + 1) / 2, w / 2, 128
    r, t = np.meshgrid(rq, 2 * np.pi * np.arange(nt) / nt, indexing="ij")
    f = {k: np.zeros(r.shape + (3,)) for k in ("lap", "lap_r", "lap_t", "x_r", "x_t", "x_rr", "x_rt", "x_tt")}
    pw = lambda m: r ** max(m, 0)  # noqa: E731
    for c in range(3):
        for n, a in enumerate(sol[c]):
            e = np.exp(1j * n * t) * (1 if n == 0 else 2)
            ex = [n, n + 2, n + 4]
            lap = (4 * n + 4) * a[1] * pw(n) + (8 * n + 16) * a[2] * pw(n + 2)
            lap_r = (4 * n + 4) * a[1] * n * pw(n - 1) + (8 * n + 16) * a[2] * (n + 2) * pw(n + 1)
            g = sum(a[j] * pw(ex[j]) for j in range(3))
            g_r = sum(a[j] * ex[j] * pw(ex[j] - 1) for j in range(3))
            g_rr = sum(a[j] * ex[j] * (ex[j] - 1) * pw(ex[j] - 2) for j in range(3))
            for k, v in (("lap", lap), ("lap_r", lap_r), ("lap_t", 1j * n * lap), ("x_r", g_r), ("x_t", 1j * n * g),
                         ("x_rr", g_rr), ("x_rt", 1j * n * g_r), ("x_tt", -n * n * g)):
                f[k][..., c] += (v * e).real
    da = wr[:, None] * r * (2 * np.pi / nt)
    dot = lambda a, b: (a * b).sum(-1)  # noqa: E731
    tri = ((dot(f["lap_r"], f["lap_r"]) + dot(f["lap_t"], f["lap_t"]) / r**2) * da).sum()
    thin = (dot(f["lap"], f["lap"]) * da).sum()
    e_, f_, g_ = dot(f["x_r"], f["x_r"]), dot(f["x_r"], f["x_t"]), dot(f["x_t"], f["x_t"])
    nrm = np.cross(f["x_r"], f["x_t"])
    jac = np.linalg.norm(nrm, axis=-1)
    nrm /= jac[..., None]
    h = (e_ * dot(f["x_tt"], nrm) - 2 * f_ * dot(f["x_rt"], nrm) + g_ * dot(f["x_rr"], nrm)) / (2 * (e_ * g_ - f_**2))
    willmore = (h**2 * jac * wr[:, None] * (2 * np.pi / nt)).sum()
    return tri, thin, willmore


def chosen(make, dist):
    """On a 7 × 11 grid of (f, μ): the smallest distance, and the distance of each energy's choice."""
    rows = np.array([(dist(s), *energies(s)) for s in (make(f, mu) for f in np.linspace(0.7, 1.3, 7)
                                                       for mu in np.linspace(-1.5, 1, 11))])
    return f"best {rows[:, 0].min():.2e}; chosen by " + ", ".join(
        f"{name} {rows[rows[:, k].argmin(), 0]:.2e}" for k, name in ((3, "Willmore"), (2, "thin plate"), (1, "triharmonic")))


def best(run):
    return min((run(f, mu), f, mu) for f in np.linspace(0.7, 1.3, 13) for mu in np.linspace(-1.5, 1, 26))


def main():
    if "--select" in sys.argv:
        pick = lambda run: chosen(lambda f, mu: run(f, mu)[0], run(1.0, 0.0)[1])  # noqa: E731
        print("height field, ellipse 0.6 x 0.5, arc length:", pick(lambda f, mu: height_field(0.6, 0.5, True, f, mu, True)))
        for deg in (18, 35):
            print(f"sphere cap {deg}°:", pick(lambda f, mu: sphere_cap(np.radians(deg), f, mu, True)))
        for name, (u0, w0) in (("top", (0.0, np.pi / 2)), ("outer equator", (np.arctan2(1.12, -0.6), 0.0))):
            print(f"torus hole ({name}):", pick(lambda f, mu: torus_hole(u0, w0, 0.3, f, mu, True)))
        return
    for a, b in ((0.45, 0.3), (0.6, 0.5)):
        print(f"height field, ellipse {a} x {b}: affine angle {height_field(a, b, False):.2e}, "
              f"arc length {height_field(a, b, True):.2e}")
    for deg in (18, 25, 35):
        al = np.radians(deg)
        print(f"sphere cap {deg}°: f = 1, μ = 0: {sphere_cap(al):.2e}; best on the grid {best(lambda f, m: sphere_cap(al, f, m))}")
    for name, (u0, w0) in (("top", (0.0, np.pi / 2)), ("outer equator", (np.arctan2(1.12, -0.6), 0.0))):
        print(f"torus hole ({name}): f = 1, μ = 0: {torus_hole(u0, w0, 0.3):.2e}; "
              f"best on the grid {best(lambda f, m: torus_hole(u0, w0, 0.3, f, m))}")


if __name__ == "__main__":
    main()
