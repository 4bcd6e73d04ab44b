"""Warp kernels for cell-centred transported scalars (the k and omega of a turbulence model) on the
staggered MAC grid of ``kernels.cfd`` (storage convention there: [J, I], G ghost layers, the u-face
at (J, I) is the left face of cell column I, the v-face at (J, I) the bottom face of cell row J).

One row kernel advances a scalar q by one stage of an explicit Runge-Kutta scheme:

  out = (a q0 + b (q + dt (-div(q w) + div(Gamma grad q) + S_e))) / (1 + b dt S_i)

with w = u - u_grid the velocity relative to the grid (a moving body grid, ``bridge.cfd.overset``),
Gamma(x, y) > 0 a cell-centred diffusivity (face value: mean of the two cells), S_e an explicit source
and S_i >= 0 an implicit sink rate (destruction terms such as beta omega^2 = (beta omega) omega),
taken at the stage's new level (for a sink alone the SSP-RK2 stages then give q / (1 + S_i dt):
unconditionally positive, first order in time for that term).
Advection uses the limited upwind-biased face values of ``kernels.cfd.upwind_flux`` (van Leer: TVD),
so with a, b >= 0, S_e >= 0 and dt within the advective and diffusive limits, a non-negative q stays
non-negative (the positivity k and omega need). Conservative: the face fluxes telescope.
"""

import warp as wp

from kernels.cfd import polygon_nearest, polygon_signed_distance, rigid_velocity, upwind_flux
from kernels.wall_law import KAPPA, friction_uplus


@wp.func
def _xflux(q: wp.array2d(dtype=wp.float64), gam: wp.array2d(dtype=wp.float64), vel: wp.float64, J: int, I: int,
           idx: wp.float64, scheme: int):
    """Advective minus diffusive flux of q through the face between cells (J, I - 1) and (J, I)."""
    half = wp.float64(0.5)
    one = wp.float64(1.0)
    return upwind_flux(vel, q[J, I - 2], q[J, I - 1], q[J, I], q[J, I + 1], one, one, half, scheme) \
        - half * (gam[J, I - 1] + gam[J, I]) * (q[J, I] - q[J, I - 1]) * idx


@wp.func
def _face_metrics(hy_c: wp.array(dtype=wp.float64), hy_f: wp.array(dtype=wp.float64), J: int):
    """(rm, rp, w, 1 / d) of the face between rows J - 1 and J: the spacing ratios d / d_below and
    d / d_above of the limiter, the weight of row J - 1's centre, d the centre-to-centre distance."""
    d = hy_f[J]
    return wp.vec4d(d / hy_f[J - 1], d / hy_f[J + 1], wp.float64(0.5) * hy_c[J - 1] / d, wp.float64(1.0) / d)


@wp.func
def _yflux(q: wp.array2d(dtype=wp.float64), gam: wp.array2d(dtype=wp.float64), vel: wp.float64, J: int, I: int,
           m: wp.vec4d, scheme: int):
    """The same through the face between cells (J - 1, I) and (J, I) (its ``_face_metrics`` m)."""
    return upwind_flux(vel, q[J - 2, I], q[J - 1, I], q[J, I], q[J + 1, I], m[0], m[1], m[2], scheme) \
        - wp.float64(0.5) * (gam[J - 1, I] + gam[J, I]) * (q[J, I] - q[J - 1, I]) * m[3]


@wp.func
def _stage_value(q: wp.array2d(dtype=wp.float64), q0: wp.array2d(dtype=wp.float64),
                 s_e: wp.array2d(dtype=wp.float64), s_i: wp.array2d(dtype=wp.float64), J: int, I: int,
                 div_flux: wp.float64, dt: wp.float64, a: wp.float64, b: wp.float64):
    """(a q0 + b (q + dt (-div flux + S_e))) / (1 + b dt S_i) at cell (J, I)."""
    return (a * q0[J, I] + b * (q[J, I] + dt * (s_e[J, I] - div_flux))) / (wp.float64(1.0) + b * dt * s_i[J, I])


@wp.kernel
def scalar_stage(q: wp.array2d(dtype=wp.float64), u: wp.array2d(dtype=wp.float64),
                 v: wp.array2d(dtype=wp.float64), gam: wp.array2d(dtype=wp.float64),
                 s_e: wp.array2d(dtype=wp.float64), s_i: wp.array2d(dtype=wp.float64),
                 q0: wp.array2d(dtype=wp.float64), out: wp.array2d(dtype=wp.float64),
                 hy_c: wp.array(dtype=wp.float64), hy_f: wp.array(dtype=wp.float64),
                 gx_c: wp.array(dtype=wp.float64), gy_c: wp.array(dtype=wp.float64),
                 dx: wp.float64, dt: wp.float64, a: wp.float64, b: wp.float64,
                 i_lo: int, i_hi: int, row0: int, scheme: int):
    """One stage (module doc) on the cells of storage row row0 + tid, columns i_lo .. i_hi - 1.

    ``gx_c[J]``: the grid's x-velocity at the height of row J; ``gy_c[I]``: its y-velocity at the x
    of column I (zeros for a fixed grid). The x-flux is carried along the row."""
    J = row0 + wp.tid()
    one = wp.float64(1.0)
    idx = one / dx
    ihc = one / hy_c[J]
    gx = gx_c[J]
    lo = _face_metrics(hy_c, hy_f, J)        # the faces below and above the row
    hi = _face_metrics(hy_c, hy_f, J + 1)
    fl = _xflux(q, gam, u[J, i_lo] - gx, J, i_lo, idx, scheme)
    for I in range(i_lo, i_hi):
        gy = gy_c[I]
        fr = _xflux(q, gam, u[J, I + 1] - gx, J, I + 1, idx, scheme)
        fb = _yflux(q, gam, v[J, I] - gy, J, I, lo, scheme)
        ft = _yflux(q, gam, v[J + 1, I] - gy, J + 1, I, hi, scheme)
        out[J, I] = _stage_value(q, q0, s_e, s_i, J, I, (fr - fl) * idx + (ft - fb) * ihc, dt, a, b)
        fl = fr


@wp.kernel
def scalar_pair_stage(q1: wp.array2d(dtype=wp.float64), gam1: wp.array2d(dtype=wp.float64),
                      se1: wp.array2d(dtype=wp.float64), si1: wp.array2d(dtype=wp.float64),
                      q01: wp.array2d(dtype=wp.float64), out1: wp.array2d(dtype=wp.float64),
                      q2: wp.array2d(dtype=wp.float64), gam2: wp.array2d(dtype=wp.float64),
                      se2: wp.array2d(dtype=wp.float64), si2: wp.array2d(dtype=wp.float64),
                      q02: wp.array2d(dtype=wp.float64), out2: wp.array2d(dtype=wp.float64),
                      u: wp.array2d(dtype=wp.float64), v: wp.array2d(dtype=wp.float64),
                      hy_c: wp.array(dtype=wp.float64), hy_f: wp.array(dtype=wp.float64),
                      gx_c: wp.array(dtype=wp.float64), gy_c: wp.array(dtype=wp.float64),
                      dx: wp.float64, dt: wp.float64, a: wp.float64, b: wp.float64,
                      i_lo: int, i_hi: int, row0: int, scheme: int):
    """``scalar_stage`` for two scalars carried by the same velocity in one sweep (k and omega): the
    velocity and the metrics are read once for both."""
    J = row0 + wp.tid()
    one = wp.float64(1.0)
    idx = one / dx
    ihc = one / hy_c[J]
    gx = gx_c[J]
    lo = _face_metrics(hy_c, hy_f, J)
    hi = _face_metrics(hy_c, hy_f, J + 1)
    ul = u[J, i_lo] - gx
    fl1 = _xflux(q1, gam1, ul, J, i_lo, idx, scheme)
    fl2 = _xflux(q2, gam2, ul, J, i_lo, idx, scheme)
    for I in range(i_lo, i_hi):
        gy = gy_c[I]
        ur = u[J, I + 1] - gx
        vb = v[J, I] - gy
        vt = v[J + 1, I] - gy
        fr1 = _xflux(q1, gam1, ur, J, I + 1, idx, scheme)
        fr2 = _xflux(q2, gam2, ur, J, I + 1, idx, scheme)
        d1 = (fr1 - fl1) * idx + (_yflux(q1, gam1, vt, J + 1, I, hi, scheme)
                                  - _yflux(q1, gam1, vb, J, I, lo, scheme)) * ihc
        d2 = (fr2 - fl2) * idx + (_yflux(q2, gam2, vt, J + 1, I, hi, scheme)
                                  - _yflux(q2, gam2, vb, J, I, lo, scheme)) * ihc
        out1[J, I] = _stage_value(q1, q01, se1, si1, J, I, d1, dt, a, b)
        out2[J, I] = _stage_value(q2, q02, se2, si2, J, I, d2, dt, a, b)
        fl1 = fr1
        fl2 = fr2


@wp.kernel
def scalar_ghosts_x(q: wp.array2d(dtype=wp.float64), g: int, nx: int, ny: int,
                    kinds: wp.vec4i, values: wp.vec4d):
    """Left and right ghost cells of a cell-centred scalar, storage row k = tid (interior rows only).
    Sides in the order (left, right, bottom, top): kind 0 zero gradient (mirror), kind 1 the value on
    the boundary face (antisymmetric about it: second order)."""
    k = wp.tid()
    two = wp.float64(2.0)
    if k >= g and k < g + ny:
        for m in range(1, g + 1):
            if kinds[0] == 1:
                q[k, g - m] = two * values[0] - q[k, g + m - 1]
            else:
                q[k, g - m] = q[k, g + m - 1]
            if kinds[1] == 1:
                q[k, g + nx - 1 + m] = two * values[1] - q[k, g + nx - m]
            else:
                q[k, g + nx - 1 + m] = q[k, g + nx - m]


@wp.kernel
def scalar_ghosts_y(q: wp.array2d(dtype=wp.float64), g: int, ny: int, kinds: wp.vec4i, values: wp.vec4d):
    """Bottom and top ghost rows over every storage column, kinds as in ``scalar_ghosts_x`` (run after
    it: the corner ghosts then follow the bottom/top rule)."""
    I = wp.tid()
    two = wp.float64(2.0)
    for m in range(1, g + 1):
        if kinds[2] == 1:
            q[g - m, I] = two * values[2] - q[g + m - 1, I]
        else:
            q[g - m, I] = q[g + m - 1, I]
        if kinds[3] == 1:
            q[g + ny - 1 + m, I] = two * values[3] - q[g + ny - m, I]
        else:
            q[g + ny - 1 + m, I] = q[g + ny - m, I]


@wp.kernel
def cell_wall_distance(verts: wp.array(dtype=wp.vec2d), x0: wp.float64, dx: wp.float64,
                       yc: wp.array(dtype=wp.float64), nx: int, pos: wp.vec3d,
                       dist: wp.array2d(dtype=wp.float64)):
    """dist[j, i] = min(dist[j, i], |distance| of cell centre (i, j) to the polygon moved to pos =
    (x, y, theta)) (exact distance to the segments, ``kernels.cfd.polygon_signed_distance``)."""
    j = wp.tid()
    c = wp.cos(pos[2])
    s = wp.sin(pos[2])
    for i in range(nx):
        X = x0 + (wp.float64(i) + wp.float64(0.5)) * dx - pos[0]
        Y = yc[j] - pos[1]
        d = wp.abs(polygon_signed_distance(c * X + s * Y, -s * X + c * Y, verts))
        dist[j, i] = wp.min(dist[j, i], d)



@wp.func
def polygon_distance_normal(px: wp.float64, py: wp.float64, verts: wp.array(dtype=wp.vec2d)):
    """(signed distance, n_x, n_y) of (px, py) to a closed polygon: the distance as
    ``kernels.cfd.polygon_signed_distance`` (negative inside), n the unit vector from the nearest
    boundary point to the point (a normal of the nearest segment when the point lies on it)."""
    r = polygon_nearest(px, py, verts)
    k = int(r[1])
    a = verts[k]
    b = verts[(k + 1) % verts.shape[0]]
    ex = b[0] - a[0]
    ey = b[1] - a[1]
    dx = px - a[0] - r[2] * ex
    dy = py - a[1] - r[2] * ey
    d2 = dx * dx + dy * dy
    nx = wp.float64(0.0)
    ny = wp.float64(0.0)
    if d2 > wp.float64(1.0e-28):
        h = wp.sqrt(d2)
        nx = dx / h
        ny = dy / h
    else:
        h = wp.sqrt(ex * ex + ey * ey)
        nx = ey / h
        ny = -ex / h
    return wp.vec3d(r[0], nx, ny)


@wp.kernel
def body_wall_cells(verts: wp.array(dtype=wp.vec2d), pos: wp.vec3d, x0: wp.float64, dx: wp.float64,
                    yc: wp.array(dtype=wp.float64), hy_c: wp.array(dtype=wp.float64), g: int, i0: int, j0: int,
                    ni: int, reset: int, phi: wp.array2d(dtype=wp.float64), ext: wp.array2d(dtype=wp.float64),
                    dist_sides: wp.array2d(dtype=wp.float64), dist: wp.array2d(dtype=wp.float64)):
    """The cells of a box around a body moved to pos = (x, y, theta), storage rows j0 + tid, columns i0 ..
    i0 + ni - 1. ``reset`` 1: dist = dist_sides there (the distance to the box's sides only, before the
    bodies' minima). ``reset`` 0: phi = the signed distance of the cell centre to the polygon, ext = half
    the cell's extent along the wall normal, 0.5 (|n_x| dx + |n_y| dy), and dist = min(dist, |phi|)."""
    jb = wp.tid()
    J = j0 + jb
    c = wp.cos(pos[2])
    s = wp.sin(pos[2])
    for ib in range(ni):
        I = i0 + ib
        if reset != 0:
            dist[J, I] = dist_sides[J, I]
        else:
            X = x0 + (wp.float64(I - g) + wp.float64(0.5)) * dx - pos[0]
            Y = yc[J] - pos[1]
            r = polygon_distance_normal(c * X + s * Y, -s * X + c * Y, verts)
            ngx = c * r[1] - s * r[2]   # the normal in the grid's axes (the body's turned by theta)
            ngy = s * r[1] + c * r[2]
            phi[jb, ib] = r[0]
            ext[jb, ib] = wp.float64(0.5) * (wp.abs(ngx) * dx + wp.abs(ngy) * hy_c[J])
            dist[J, I] = wp.min(dist[J, I], wp.abs(r[0]))


# --- k-omega SST, the 2003 variant (Menter, Kuntz and Langtry 2003; NASA TMR "SST-2003") ----------
SST_BETA_STAR = wp.constant(wp.float64(0.09))
SST_A1 = wp.constant(wp.float64(0.31))
SST_SIGMA_K1 = wp.constant(wp.float64(0.85))
SST_SIGMA_K2 = wp.constant(wp.float64(1.0))
SST_SIGMA_W1 = wp.constant(wp.float64(0.5))
SST_SIGMA_W2 = wp.constant(wp.float64(0.856))
SST_BETA1 = wp.constant(wp.float64(0.075))
SST_BETA2 = wp.constant(wp.float64(0.0828))
SST_GAMMA1 = wp.constant(wp.float64(5.0 / 9.0))
SST_GAMMA2 = wp.constant(wp.float64(0.44))


@wp.func
def _fill_ghosts(a: wp.array2d(dtype=wp.float64), J: int, g: int, nx: int, ny: int):
    """Ghost columns of row J from its edge cells; the first (last) interior row also fills the
    ghost rows below (above) it, corners included."""
    for m in range(1, g + 1):
        a[J, g - m] = a[J, g]
        a[J, g + nx - 1 + m] = a[J, g + nx - 1]
    if J == g:
        for m in range(1, g + 1):
            for I in range(0, nx + 2 * g):
                a[g - m, I] = a[g, I]
    if J == g + ny - 1:
        for m in range(1, g + 1):
            for I in range(0, nx + 2 * g):
                a[g + ny - 1 + m, I] = a[g + ny - 1, I]


@wp.kernel
def sst_coefficients(u: wp.array2d(dtype=wp.float64), v: wp.array2d(dtype=wp.float64),
                     k: wp.array2d(dtype=wp.float64), w: wp.array2d(dtype=wp.float64),
                     dist: wp.array2d(dtype=wp.float64), nu: wp.float64,
                     hy_c: wp.array(dtype=wp.float64), yc: wp.array(dtype=wp.float64), dx: wp.float64,
                     g: int, nx: int, ny: int, row0: int,
                     nu_eff: wp.array2d(dtype=wp.float64), gam_k: wp.array2d(dtype=wp.float64),
                     gam_w: wp.array2d(dtype=wp.float64), src_k: wp.array2d(dtype=wp.float64),
                     snk_k: wp.array2d(dtype=wp.float64), src_w: wp.array2d(dtype=wp.float64),
                     snk_w: wp.array2d(dtype=wp.float64)):
    """The SST-2003 model's coefficients on the cells of storage row row0 + tid (and that row's ghost
    columns; the first and last interior rows also fill the ghost rows), for the transport of
    ``kernels.transport.scalar_stage`` (bridge/cfd/turbulence.py has the equations):
    nu_eff = nu + nu_t; k: Gamma = nu + sigma_k nu_t, S_e = min(nu_t S^2, 10 beta* k omega),
    S_i = beta* omega; omega: Gamma = nu + sigma_w nu_t, S_e = gamma S^2 + max(CD, 0),
    S_i = beta omega + max(-CD, 0) / omega, CD = 2 (1 - F1) sigma_w2 grad k . grad omega / omega."""
    J = row0 + wp.tid()
    half = wp.float64(0.5)
    one = wp.float64(1.0)
    two = wp.float64(2.0)
    tiny = wp.float64(1.0e-30)
    idx = one / dx
    ihc = one / hy_c[J]
    iyy = one / (yc[J + 1] - yc[J - 1])
    for I in range(g, g + nx):
        dudx = (u[J, I + 1] - u[J, I]) * idx
        dvdy = (v[J + 1, I] - v[J, I]) * ihc
        dudy = half * ((u[J + 1, I] + u[J + 1, I + 1]) - (u[J - 1, I] + u[J - 1, I + 1])) * iyy
        dvdx = half * ((v[J, I + 1] + v[J + 1, I + 1]) - (v[J, I - 1] + v[J + 1, I - 1])) * half * idx
        s2 = two * (dudx * dudx + dvdy * dvdy) + (dudy + dvdx) * (dudy + dvdx)
        kk = wp.max(k[J, I], wp.float64(0.0))
        ww = wp.max(w[J, I], tiny)
        d = dist[J, I]
        dkx = (k[J, I + 1] - k[J, I - 1]) * half * idx
        dky = (k[J + 1, I] - k[J - 1, I]) * iyy
        dwx = (w[J, I + 1] - w[J, I - 1]) * half * idx
        dwy = (w[J + 1, I] - w[J - 1, I]) * iyy
        grad_kw = dkx * dwx + dky * dwy
        cd_kw = wp.max(two * SST_SIGMA_W2 * grad_kw / ww, wp.float64(1.0e-10))
        sk = wp.sqrt(kk)
        arg1 = wp.min(wp.max(sk / (SST_BETA_STAR * ww * d), wp.float64(500.0) * nu / (d * d * ww)),
                      wp.float64(4.0) * SST_SIGMA_W2 * kk / (cd_kw * d * d))
        f1 = wp.tanh(arg1 * arg1 * arg1 * arg1)
        arg2 = wp.max(two * sk / (SST_BETA_STAR * ww * d), wp.float64(500.0) * nu / (d * d * ww))
        f2 = wp.tanh(arg2 * arg2)
        nut = SST_A1 * kk / wp.max(SST_A1 * ww, wp.sqrt(s2) * f2)
        sigma_k = f1 * SST_SIGMA_K1 + (one - f1) * SST_SIGMA_K2
        sigma_w = f1 * SST_SIGMA_W1 + (one - f1) * SST_SIGMA_W2
        beta = f1 * SST_BETA1 + (one - f1) * SST_BETA2
        gamma = f1 * SST_GAMMA1 + (one - f1) * SST_GAMMA2
        cross = two * (one - f1) * SST_SIGMA_W2 * grad_kw / ww
        nu_eff[J, I] = nu + nut
        gam_k[J, I] = nu + sigma_k * nut
        gam_w[J, I] = nu + sigma_w * nut
        src_k[J, I] = wp.min(nut * s2, wp.float64(10.0) * SST_BETA_STAR * kk * ww)
        snk_k[J, I] = SST_BETA_STAR * ww
        src_w[J, I] = gamma * s2 + wp.max(cross, wp.float64(0.0))
        snk_w[J, I] = beta * ww + wp.max(-cross, wp.float64(0.0)) / ww
    _fill_ghosts(nu_eff, J, g, nx, ny)
    _fill_ghosts(gam_k, J, g, nx, ny)
    _fill_ghosts(gam_w, J, g, nx, ny)
    _fill_ghosts(src_k, J, g, nx, ny)
    _fill_ghosts(snk_k, J, g, nx, ny)
    _fill_ghosts(src_w, J, g, nx, ny)
    _fill_ghosts(snk_w, J, g, nx, ny)


SST_HOLD = wp.constant(wp.float64(1.0e30))   # the rate that holds a cell at a value (source R q, sink R)
SST_YPLUS_LOG = wp.constant(wp.float64(10.8))   # y+ where the log law (0.41, 5.0) meets u+ = y+


@wp.kernel
def sst_body_walls(phi: wp.array2d(dtype=wp.float64), ext: wp.array2d(dtype=wp.float64), i0: int, j0: int,
                   ni: int, k: wp.array2d(dtype=wp.float64), w: wp.array2d(dtype=wp.float64),
                   u: wp.array2d(dtype=wp.float64), v: wp.array2d(dtype=wp.float64), x0: wp.float64,
                   dx: wp.float64, yc: wp.array(dtype=wp.float64), g: int, pos: wp.vec3d, vel: wp.vec3d,
                   nu: wp.float64, function: int, src_k: wp.array2d(dtype=wp.float64),
                   snk_k: wp.array2d(dtype=wp.float64), src_w: wp.array2d(dtype=wp.float64),
                   snk_w: wp.array2d(dtype=wp.float64), nu_eff: wp.array2d(dtype=wp.float64),
                   gam_k: wp.array2d(dtype=wp.float64), gam_w: wp.array2d(dtype=wp.float64)):
    """The wall of an immersed body in the SST model (bridge/cfd/turbulence.py), on the box of
    ``body_wall_cells`` (its phi and ext): the sources of the cells that are held at a value (source
    R q_w, implicit sink R, R = SST_HOLD, so the stage gives q_w to round-off).

    Cells inside the body (phi <= 0): omega = 60 nu / (beta_1 (2 ext)^2) (Menter's wall value over a
    cell's extent across the wall) and k = 0 for a resolved wall (``function`` 0); with the wall
    function, the cells next to the fluid take the means of their fluid neighbours' k and omega (no flux
    of either into the wall, and the eddy viscosity of the wall's fluid cells, not k over Menter's
    omega: at Re 1e8 that is 1e-2 omega_log, and the thousandfold nu_t inside the body set the time
    step), the others k = 0 and Menter's omega.
    With the wall function (``function`` 1), fluid cells whose centre lies within a cell's extent of the
    wall (phi <= 2 ext): omega = sqrt(omega_vis^2 + omega_log^2), omega_vis = 6 nu / (beta_1 phi^2),
    omega_log = sqrt(k) / (beta*^(1/4) kappa phi) - the sublayer and log-layer solutions, blended - and
    the k production of the log layer, P = tau_w du/dn = u_tau^2 beta*^(1/4) sqrt(k) / (kappa phi), with
    u_tau from the cell's speed relative to the body (pos, vel: the body's pose and velocity) on
    Spalding's law, where the cell lies in the log layer (y+ > 10.8, where ln(y+)/0.41 + 5 meets y+; below,
    the model's own production): the strain rate of the cell itself spans the wall and would overstate
    it. The production keeps the model's limiter, 10 beta* k omega. With ``function`` 2 ("equilibrium")
    the production is the law's own, P = tau_w du/dn = u_tau^3 / (kappa phi), with no limiter: it does
    not scale with the cell's k (the other form and its limiter go as sqrt(k) and k^1.5, so a layer that
    enters with the freestream's k stays laminar), so the layer turns turbulent where its first cell lies
    in the log layer, and k settles where P meets the destruction beta* k omega_log: k = u_tau^2 /
    sqrt(beta*), nu_t = kappa u_tau phi, the law's eddy viscosity (the k-omega log-layer solution;
    Wilcox 2006, "Turbulence Modeling for CFD", 3rd ed., ch. 4). These cells take nu_t = k / omega
    unlimited, for the strain rate's reason (the limiter a1 k / (S F2) would act on that overstated S and
    halve the eddy viscosity that carries the wall shear), with the inner diffusivities (F1 = 1 at a wall)."""
    jb = wp.tid()
    J = j0 + jb
    nj = phi.shape[0]
    zero = wp.float64(0.0)
    for ib in range(ni):
        I = i0 + ib
        ph = phi[jb, ib]
        e = ext[jb, ib]
        if ph <= zero:
            kt = zero
            wt = wp.float64(15.0) * nu / (SST_BETA1 * e * e)
            if function != 0:
                acc = wp.float64(0.0)
                acc_w = wp.float64(0.0)
                cnt = wp.float64(0.0)
                for m in range(4):
                    di = int(0)  # noqa: UP018 (Warp dynamic variable)
                    dj = int(0)  # noqa: UP018 (Warp dynamic variable)
                    if m == 0:
                        di = -1
                    elif m == 1:
                        di = 1
                    elif m == 2:
                        dj = -1
                    else:
                        dj = 1
                    if ib + di >= 0 and ib + di < ni and jb + dj >= 0 and jb + dj < nj:
                        if phi[jb + dj, ib + di] > zero:
                            acc += wp.max(k[J + dj, I + di], zero)
                            acc_w += wp.max(w[J + dj, I + di], zero)
                            cnt += wp.float64(1.0)
                if cnt > zero:
                    kt = acc / cnt
                    if acc_w > zero:
                        wt = acc_w / cnt
            src_k[J, I] = SST_HOLD * kt
            snk_k[J, I] = SST_HOLD
            src_w[J, I] = SST_HOLD * wt
            snk_w[J, I] = SST_HOLD
        elif function != 0 and ph <= wp.float64(2.0) * e:
            sk = wp.sqrt(wp.max(k[J, I], zero))
            w_vis = wp.float64(6.0) * nu / (SST_BETA1 * ph * ph)
            w_log = sk / (wp.sqrt(wp.sqrt(SST_BETA_STAR)) * KAPPA * ph)
            w_wall = wp.sqrt(w_vis * w_vis + w_log * w_log)
            src_w[J, I] = SST_HOLD * w_wall
            snk_w[J, I] = SST_HOLD
            nut = sk * sk / w_wall
            nu_eff[J, I] = nu + nut
            gam_k[J, I] = nu + SST_SIGMA_K1 * nut
            gam_w[J, I] = nu + SST_SIGMA_W1 * nut
            xc = x0 + (wp.float64(I - g) + wp.float64(0.5)) * dx
            ur = wp.float64(0.5) * (u[J, I] + u[J, I + 1]) - rigid_velocity(xc, yc[J], pos, vel, 0)
            vr = wp.float64(0.5) * (v[J, I] + v[J + 1, I]) - rigid_velocity(xc, yc[J], pos, vel, 1)
            speed = wp.sqrt(ur * ur + vr * vr)
            up = friction_uplus(speed * ph / nu)
            if up > zero:
                u_tau = speed / up
                if ph * u_tau > SST_YPLUS_LOG * nu:   # in the log layer; below it the model's own production
                    if function == 2:   # the law's own: tau_w du/dn = u_tau^3 / (kappa phi), whatever k is
                        src_k[J, I] = u_tau * u_tau * u_tau / (KAPPA * ph)
                    else:
                        src_k[J, I] = wp.min(u_tau * u_tau * wp.sqrt(wp.sqrt(SST_BETA_STAR)) * sk / (KAPPA * ph),
                                             wp.float64(10.0) * SST_BETA_STAR * sk * sk * w_log)
