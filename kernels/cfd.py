"""Warp kernels of the 2D incompressible Navier-Stokes solver (staggered MAC grid).

Only pointwise maths (``@wp.func``) and thin row kernels live here; ``bridge.cfd`` launches them.

Storage convention (see ``bridge.cfd.grids``): arrays are indexed ``[J, I]`` (row = y) with ``G``
ghost layers; cell (i, j) is stored at (J, I) = (j + G, i + G); the u-face at storage (J, I) is the
LEFT face of cell column I; the v-face at storage (J, I) is the BOTTOM face of cell row J.

Kernel shape: one thread per row with an inner loop over the columns (2x faster on the CPU backend
than a 2D ``wp.tid()``; see docs/warp_cpu.md); ``row0`` lets the launcher split the rows over threads.
Every kernel also runs unchanged on "cuda" (one thread per row there too).

Kernels are typed for float64 (the project's CFD precision, ``bridge.cfd.precision``).
"""

import warp as wp

from kernels.wall_law import wall_law_eddy_viscosity, wall_law_ratio

# Advection schemes (integer codes used inside kernels; names in bridge.cfd.advection).
SCHEME_CENTRAL = 0
SCHEME_VANLEER = 1

# IB face states.
IB_FLUID = 0
IB_SOLID = 1
IB_INTERFACE = 2


@wp.func
def limited_face_value(q_u: wp.float64, q_c: wp.float64, q_d: wp.float64,
                       ratio: wp.float64, w_cf: wp.float64, scheme: int):
    """Face value from the upwind point C towards the downwind point D (MUSCL form).

    q_f = q_c + psi(r) w_cf (q_d - q_c), r = ((q_c - q_u)/d_uc) / ((q_d - q_c)/d_cd),
    ratio = d_cd/d_uc, w_cf = distance C->face / d_cd (1/2 on a uniform grid).
    central: psi = 1 (linear interpolation, second order); vanleer: psi = (r + |r|)/(1 + |r|)
    (van Leer 1974; TVD, second order where smooth, monotone at extrema). With s = (q_c - q_u) ratio
    the van Leer increment psi (q_d - q_c) is 2 s (q_d - q_c)/(s + q_d - q_c) when s (q_d - q_c) > 0,
    else 0: one division per face (divisions dominate the scalar CPU loop).
    """
    dq = q_d - q_c
    if scheme == 0:
        return q_c + w_cf * dq
    sl = (q_c - q_u) * ratio
    inc = wp.float64(0.0)
    if sl * dq > wp.float64(0.0):
        inc = wp.float64(2.0) * sl * dq / (sl + dq)
    return q_c + w_cf * inc


@wp.func
def upwind_flux(vel: wp.float64, q_m2: wp.float64, q_m1: wp.float64, q_p1: wp.float64, q_p2: wp.float64,
                r_m: wp.float64, r_p: wp.float64, w_m: wp.float64, scheme: int):
    """Advective flux vel*q at a face between points m1 (behind) and p1 (ahead).

    r_m = d_0/d_m, r_p = d_0/d_p with spacings d_m (m2-m1), d_0 (m1-p1), d_p (p1-p2);
    w_m = distance m1->face / d_0.
    """
    q = wp.float64(0.0)
    if vel >= wp.float64(0.0):
        q = limited_face_value(q_m2, q_m1, q_p1, r_m, w_m, scheme)
    else:
        q = limited_face_value(q_p2, q_p1, q_m1, r_p, wp.float64(1.0) - w_m, scheme)
    return vel * q


@wp.func
def yflux_u_row(u: wp.array2d(dtype=wp.float64), v: wp.array2d(dtype=wp.float64),
                nu: wp.array2d(dtype=wp.float64), hy_c: wp.array(dtype=wp.float64),
                hy_f: wp.array(dtype=wp.float64), dx: wp.float64, J: int, i_lo: int, i_hi: int, scheme: int,
                gy_u: wp.array(dtype=wp.float64), flux: wp.array2d(dtype=wp.float64), frow: int):
    """y-flux of x-momentum (advective - viscous) at the corners of v-face row J, u columns I, into
    ``flux[frow, I]``: computed once per corner and shared by the u-faces above and below. The
    advecting velocity is relative to the grid (``gy_u[I]``: the grid's y-velocity on u column I)."""
    half = wp.float64(0.5)
    one = wp.float64(1.0)
    ihf = one / hy_f[J]
    idx = one / dx
    rm = hy_f[J] / hy_f[J - 1]
    rp = hy_f[J] / hy_f[J + 1]
    w = half * hy_c[J - 1] * ihf
    # v and the column sum of nu left of the corner are carried along the row (one load each per corner)
    vl = v[J, i_lo - 1]
    nl = nu[J - 1, i_lo - 1] + nu[J, i_lo - 1]
    for I in range(i_lo, i_hi):
        vr = v[J, I]
        nr = nu[J - 1, I] + nu[J, I]
        ub = u[J - 1, I]
        ua = u[J, I]
        flux[frow, I] = upwind_flux(half * (vl + vr) - gy_u[I], u[J - 2, I], ub, ua, u[J + 1, I], rm, rp, w, scheme) \
            - wp.float64(0.25) * (nl + nr) * ((ua - ub) * ihf + (vr - vl) * idx)
        vl = vr
        nl = nr


@wp.func
def yflux_v_row(v: wp.array2d(dtype=wp.float64), nu: wp.array2d(dtype=wp.float64),
                hy_c: wp.array(dtype=wp.float64), J: int, i_lo: int, i_hi: int, scheme: int,
                gy_c: wp.array(dtype=wp.float64), flux: wp.array2d(dtype=wp.float64), frow: int):
    """y-flux of y-momentum (advective - viscous) at the cell centres of row J into ``flux[frow, I]``,
    shared by the v-faces J and J+1 (advecting velocity relative to the grid: ``gy_c[I]``, the grid's
    y-velocity on cell column I)."""
    half = wp.float64(0.5)
    ihc = wp.float64(1.0) / hy_c[J]
    rm = hy_c[J] / hy_c[J - 1]
    rp = hy_c[J] / hy_c[J + 1]
    for I in range(i_lo, i_hi):
        vc = half * (v[J, I] + v[J + 1, I]) - gy_c[I]
        flux[frow, I] = upwind_flux(vc, v[J - 1, I], v[J, I], v[J + 1, I], v[J + 2, I], rm, rp, half, scheme) \
            - wp.float64(2.0) * nu[J, I] * (v[J + 1, I] - v[J, I]) * ihc


@wp.func
def block_rows(b: int, n_blocks: int, j_start: int, n_rows: int):
    """First and one-past-last row of block b when n_rows rows from j_start are cut into n_blocks."""
    return j_start + (n_rows * b) // n_blocks, j_start + (n_rows * (b + 1)) // n_blocks


@wp.kernel
def predict_u(u: wp.array2d(dtype=wp.float64), v: wp.array2d(dtype=wp.float64),
              p: wp.array2d(dtype=wp.float64), nu: wp.array2d(dtype=wp.float64),
              u0: wp.array2d(dtype=wp.float64), out: wp.array2d(dtype=wp.float64),
              hy_c: wp.array(dtype=wp.float64), hy_f: wp.array(dtype=wp.float64),
              dx: wp.float64, dt: wp.float64, a: wp.float64, b: wp.float64,
              i_lo: int, i_hi: int, j_start: int, n_rows: int, n_blocks: int, use_p: int, scheme: int,
              block0: int, scratch: wp.array2d(dtype=wp.float64),
              gx_c: wp.array(dtype=wp.float64), gx_f: wp.array(dtype=wp.float64),
              gy_c: wp.array(dtype=wp.float64), gy_u: wp.array(dtype=wp.float64), om: wp.float64):
    """out = a*u0 + b*(u + dt*(-div(u w) + div(2 nu S)_x [- dp/dx] + om v)) on the u-faces of a block
    of rows, w = u - u_grid.

    Conservative advection (limited upwind-biased) and the full variable-viscosity stress
    nu (grad u + grad u^T) so an eddy viscosity nu_t(x, y) plugs in through ``nu``; the pressure
    gradient only when ``use_p`` (incremental form). Thread index + ``block0`` = block number: the
    block's rows run bottom to top; the y-flux row above each row (``yflux_u_row``) goes to one of the
    block's two ``scratch`` rows and serves as the row below for the next row (computed once, read
    from cache); the x-flux is carried along the row.

    Moving frame (``bridge.cfd.overset``): the grid moves rigidly with velocity u_grid = (gx, gy)
    (``gx_c[J]``/``gx_f[J]``: x-velocity at the heights of cell centres / v-faces of storage row J;
    ``gy_c[I]``/``gy_u[I]``: y-velocity at the x of cell centres / u-faces of storage column I) and
    turns at ``om``; (u, v) are the absolute velocity in the grid's axes, advected by the velocity
    relative to the grid, with the source -om x u of the turning axes. A fixed grid passes zeros.
    """
    blk = block0 + wp.tid()
    r0, r1 = block_rows(blk, n_blocks, j_start, n_rows)
    half = wp.float64(0.5)
    one = wp.float64(1.0)
    two = wp.float64(2.0)
    idx = one / dx
    s = 2 * blk
    yflux_u_row(u, v, nu, hy_c, hy_f, dx, r0, i_lo, i_hi, scheme, gy_u, scratch, s)
    for J in range(r0, r1):
        lo = s + (J - r0) % 2
        hi = s + (J - r0 + 1) % 2
        yflux_u_row(u, v, nu, hy_c, hy_f, dx, J + 1, i_lo, i_hi, scheme, gy_u, scratch, hi)
        ihc = one / hy_c[J]
        gx = gx_c[J]
        # u[J, I-1 .. I+2] carried in registers along the row: one new load per face
        I = i_lo
        qm = u[J, I - 2]
        qc = u[J, I - 1]
        qp = u[J, I]
        qpp = u[J, I + 1]
        fl = upwind_flux(half * (qc + qp) - gx, qm, qc, qp, qpp, one, one, half, scheme) \
            - two * nu[J, I - 1] * (qp - qc) * idx
        for I in range(i_lo, i_hi):
            qm = qc
            qc = qp
            qp = qpp
            qpp = u[J, I + 2]
            fr = upwind_flux(half * (qc + qp) - gx, qm, qc, qp, qpp, one, one, half, scheme) \
                - two * nu[J, I] * (qp - qc) * idx
            rhs = -(fr - fl) * idx - (scratch[hi, I] - scratch[lo, I]) * ihc
            if use_p != 0:
                rhs -= (p[J, I] - p[J, I - 1]) * idx
            if om != wp.float64(0.0):
                rhs += om * wp.float64(0.25) * (v[J, I - 1] + v[J, I] + v[J + 1, I - 1] + v[J + 1, I])
            out[J, I] = a * u0[J, I] + b * (qc + dt * rhs)
            fl = fr


@wp.kernel
def predict_v(u: wp.array2d(dtype=wp.float64), v: wp.array2d(dtype=wp.float64),
              p: wp.array2d(dtype=wp.float64), nu: wp.array2d(dtype=wp.float64),
              v0: wp.array2d(dtype=wp.float64), out: wp.array2d(dtype=wp.float64),
              hy_c: wp.array(dtype=wp.float64), hy_f: wp.array(dtype=wp.float64),
              dx: wp.float64, dt: wp.float64, a: wp.float64, b: wp.float64,
              i_lo: int, i_hi: int, j_start: int, n_rows: int, n_blocks: int, use_p: int, scheme: int,
              block0: int, scratch: wp.array2d(dtype=wp.float64),
              gx_c: wp.array(dtype=wp.float64), gx_f: wp.array(dtype=wp.float64),
              gy_c: wp.array(dtype=wp.float64), gy_u: wp.array(dtype=wp.float64), om: wp.float64):
    """out = a*v0 + b*(v + dt*(-div(v w) + div(2 nu S)_y [- dp/dy] - om u)) on the v-faces of a block
    of rows (blocks, scratch rows, ``use_p`` and the moving frame as in ``predict_u``; the y-fluxes
    at the cell centres below and above face row J come from ``yflux_v_row`` rows J-1 and J; x-flux
    carried along the row)."""
    blk = block0 + wp.tid()
    r0, r1 = block_rows(blk, n_blocks, j_start, n_rows)
    half = wp.float64(0.5)
    one = wp.float64(1.0)
    quarter = wp.float64(0.25)
    idx = one / dx
    s = 2 * blk
    yflux_v_row(v, nu, hy_c, r0 - 1, i_lo, i_hi, scheme, gy_c, scratch, s)
    for J in range(r0, r1):
        lo = s + (J - r0) % 2
        hi = s + (J - r0 + 1) % 2
        yflux_v_row(v, nu, hy_c, J, i_lo, i_hi, scheme, gy_c, scratch, hi)
        ihf = one / hy_f[J]
        gx = gx_f[J]
        # weights of u rows J-1 and J at the corner height (face row J)
        wl = half * hy_c[J] * ihf
        wu = half * hy_c[J - 1] * ihf
        # v[J, I-1 .. I+2] and the column sum of nu are carried in registers along the row (one new
        # load of each per face); u below/above the right corner is loaded once per face
        I = i_lo
        qm = v[J, I - 2]
        qc = v[J, I - 1]
        qp = v[J, I]
        qpp = v[J, I + 1]
        ub = u[J - 1, I]
        ua = u[J, I]
        nsum = nu[J - 1, I] + nu[J, I]
        nul = quarter * (nu[J - 1, I - 1] + nu[J, I - 1] + nsum)
        fl = upwind_flux(wl * ub + wu * ua - gx, qm, qc, qp, qpp, one, one, half, scheme) \
            - nul * ((qp - qc) * idx + (ua - ub) * ihf)
        for I in range(i_lo, i_hi):
            qm = qc
            qc = qp
            qp = qpp
            qpp = v[J, I + 2]
            ubl = ub
            ual = ua
            ub = u[J - 1, I + 1]
            ua = u[J, I + 1]
            nnext = nu[J - 1, I + 1] + nu[J, I + 1]
            nur = quarter * (nsum + nnext)
            nsum = nnext
            fr = upwind_flux(wl * ub + wu * ua - gx, qm, qc, qp, qpp, one, one, half, scheme) \
                - nur * ((qp - qc) * idx + (ua - ub) * ihf)
            rhs = -(fr - fl) * idx - (scratch[hi, I] - scratch[lo, I]) * ihf
            if use_p != 0:
                rhs -= (p[J, I] - p[J - 1, I]) * ihf
            if om != wp.float64(0.0):
                rhs -= om * half * (wl * (ubl + ub) + wu * (ual + ua))
            out[J, I] = a * v0[J, I] + b * (qc + dt * rhs)
            fl = fr


@wp.kernel
def divergence(u: wp.array2d(dtype=wp.float64), v: wp.array2d(dtype=wp.float64),
               hy_c: wp.array(dtype=wp.float64), dx: wp.float64, scale: wp.float64, g: int, nx: int,
               row0: int, div: wp.array2d(dtype=wp.float64)):
    """div[j, i] = scale * (D u)_cell, interior cells only (no ghosts in ``div``)."""
    j = row0 + wp.tid()
    J = j + g
    sx = scale / dx
    sy = scale / hy_c[J]
    ul = u[J, g]
    for i in range(nx):
        I = i + g
        ur = u[J, I + 1]
        div[j, i] = sx * (ur - ul) + sy * (v[J + 1, I] - v[J, I])
        ul = ur


@wp.kernel
def project(ustar: wp.array2d(dtype=wp.float64), vstar: wp.array2d(dtype=wp.float64),
            phi: wp.array2d(dtype=wp.float64), hy_f: wp.array(dtype=wp.float64),
            dx: wp.float64, c: wp.float64, g: int, nx: int, ny: int, accumulate: int, row0: int,
            u: wp.array2d(dtype=wp.float64), v: wp.array2d(dtype=wp.float64),
            p: wp.array2d(dtype=wp.float64)):
    """u = u* - c grad(phi) on interior faces (boundary faces copied); p = phi, or p += phi when
    ``accumulate`` (incremental pressure); one cell row."""
    j = row0 + wp.tid()
    J = j + g
    cx = c / dx
    cy = c / hy_f[J]
    u[J, g] = ustar[J, g]
    u[J, g + nx] = ustar[J, g + nx]
    jm = wp.max(j - 1, 0)  # the bottom row's v-faces are boundary faces: copied (cy = 0)
    if j == 0:
        cy = wp.float64(0.0)
    pl = phi[j, 0]
    for i in range(nx):  # one pass over the row: v-face, u-face and pressure of each cell
        I = i + g
        ph = phi[j, i]
        v[J, I] = vstar[J, I] - cy * (ph - phi[jm, i])
        if i > 0:
            u[J, I] = ustar[J, I] - cx * (ph - pl)
        pl = ph
        if accumulate != 0:
            p[J, I] = p[J, I] + ph
        else:
            p[J, I] = ph
    if j == ny - 1:
        for i in range(nx):
            v[J + 1, i + g] = vstar[J + 1, i + g]


# ----------------------------------------------------------------------------- boundary conditions
# Side codes: 0 slip (zero normal velocity, zero tangential gradient), 1 no-slip wall,
# 2 inflow (Dirichlet, left only), 3 convective outflow (right only), 4 given (face values kept).

@wp.kernel
def bc_y_sides(u: wp.array2d(dtype=wp.float64), v: wp.array2d(dtype=wp.float64),
               g: int, nx: int, ny: int, bottom: int, top: int):
    """Ghost rows at bottom and top for every storage column; normal v-faces on the walls = 0."""
    I = wp.tid()
    jb = g  # first interior row
    jt = g + ny - 1
    for k in range(1, g + 1):
        # u ghosts: mirror (slip) or antisymmetric (no-slip)
        if I < u.shape[1]:
            if bottom == 1:
                u[jb - k, I] = -u[jb + k - 1, I]
            else:
                u[jb - k, I] = u[jb + k - 1, I]
            if top == 1:
                u[jt + k, I] = -u[jt - k + 1, I]
            else:
                u[jt + k, I] = u[jt - k + 1, I]
        if I < v.shape[1]:
            v[g - k, I] = -v[g + k, I]
            v[g + ny + k, I] = -v[g + ny - k, I]
    if I < v.shape[1]:
        v[g, I] = wp.float64(0.0)
        v[g + ny, I] = wp.float64(0.0)


@wp.kernel
def bc_x_sides(u: wp.array2d(dtype=wp.float64), v: wp.array2d(dtype=wp.float64),
               g: int, nx: int, left: int, right: int):
    """Ghost columns at left and right for every storage row (normal u-faces set by the caller)."""
    J = wp.tid()
    il = g
    ir = g + nx
    for k in range(1, g + 1):
        if J < u.shape[0]:
            if left == 0:  # slip wall: antisymmetric normal velocity about the wall face
                u[J, il - k] = -u[J, il + k]
            else:  # inflow: constant extrapolation of the prescribed face value
                u[J, il - k] = u[J, il]
            if right == 0:
                u[J, ir + k] = -u[J, ir - k]
            else:  # outflow: zero-gradient continuation
                u[J, ir + k] = u[J, ir]
        if J < v.shape[0]:
            # tangential velocity: mirror at slip walls and outflow, v = 0 at the inflow
            if left == 2 or left == 1:
                v[J, il - k] = -v[J, il + k - 1]
            else:
                v[J, il - k] = v[J, il + k - 1]
            if right == 1:
                v[J, ir + k - 1] = -v[J, ir - k]
            else:
                v[J, ir + k - 1] = v[J, ir - k]


@wp.kernel
def set_inflow(u: wp.array2d(dtype=wp.float64), profile: wp.array(dtype=wp.float64), g: int):
    """u on the left boundary faces = profile[j]."""
    j = wp.tid()
    u[j + g, g] = profile[j]


@wp.kernel
def convective_outflow(u0: wp.array2d(dtype=wp.float64), u: wp.array2d(dtype=wp.float64),
                       out: wp.array2d(dtype=wp.float64), dx: wp.float64, dt: wp.float64,
                       a: wp.float64, b: wp.float64, speed: wp.float64, g: int, nx: int):
    """du/dt + U_c du/dx = 0 on the right boundary faces, same RK stage form as the interior."""
    j = wp.tid()
    J = j + g
    I = g + nx
    out[J, I] = a * u0[J, I] + b * (u[J, I] - dt * speed * (u[J, I] - u[J, I - 1]) / dx)


@wp.kernel
def boundary_fluxes(u: wp.array2d(dtype=wp.float64), hy_c: wp.array(dtype=wp.float64), g: int, nx: int,
                    flux: wp.array(dtype=wp.float64)):
    """flux[0] += inflow volume flux, flux[1] += outflow volume flux (per row, atomic)."""
    j = wp.tid()
    J = j + g
    wp.atomic_add(flux, 0, u[J, g] * hy_c[J])
    wp.atomic_add(flux, 1, u[J, g + nx] * hy_c[J])


@wp.kernel
def shift_outflow(u: wp.array2d(dtype=wp.float64), delta: wp.float64, g: int, nx: int):
    """Add a uniform correction to the outflow faces so the volume flux balances."""
    j = wp.tid()
    u[j + g, g + nx] = u[j + g, g + nx] + delta


# ----------------------------------------------------------------------------- immersed boundary

@wp.func
def polygon_nearest(px: wp.float64, py: wp.float64, verts: wp.array(dtype=wp.vec2d)):
    """(signed distance, k, t) from (px, py) to a closed polygon: the distance negative inside (even-odd
    rule), k the nearest segment (verts[k] -> verts[k + 1], as a float; the first of equals) and t in
    [0, 1] the nearest point's place on it."""
    n = verts.shape[0]
    dmin = wp.float64(1.0e300)
    kmin = int(0)  # noqa: UP018 (Warp: a dynamic variable, mutated in the loop)
    tmin = wp.float64(0.0)
    inside = int(0)  # noqa: UP018 (Warp: a dynamic variable, mutated in the loop)
    for k in range(n):
        a = verts[k]
        b = verts[(k + 1) % n]
        ex = b[0] - a[0]
        ey = b[1] - a[1]
        wx = px - a[0]
        wy = py - a[1]
        t = wp.clamp((wx * ex + wy * ey) / (ex * ex + ey * ey), wp.float64(0.0), wp.float64(1.0))
        dx = wx - t * ex
        dy = wy - t * ey
        d2 = dx * dx + dy * dy
        if d2 < dmin:
            dmin = d2
            kmin = k
            tmin = t
        if (a[1] > py) != (b[1] > py):
            xc = a[0] + (py - a[1]) * ex / ey
            if px < xc:
                inside = 1 - inside
    d = wp.sqrt(dmin)
    if inside == 1:
        d = -d
    return wp.vec3d(d, wp.float64(kmin), tmin)


@wp.func
def polygon_signed_distance(px: wp.float64, py: wp.float64, verts: wp.array(dtype=wp.vec2d)):
    """Signed distance from (px, py) to a closed polygon (negative inside; even-odd rule)."""
    return polygon_nearest(px, py, verts)[0]


@wp.kernel
def ib_level_set(verts: wp.array(dtype=wp.vec2d), x0: wp.float64, dx: wp.float64, xoff: wp.float64,
                 yc: wp.array(dtype=wp.float64), pos: wp.vec3d, i0: int, j0: int, ni: int,
                 phi: wp.array2d(dtype=wp.float64)):
    """phi[jb, ib] = signed distance of the face (I = i0 + ib, J = j0 + jb) to the moved polygon.

    Face x = x0 + (I + xoff) dx, face y = yc[J]; pos = (x_ref, y_ref, theta) of the body frame.
    """
    jb = wp.tid()
    c = wp.cos(pos[2])
    s = wp.sin(pos[2])
    for ib in range(ni):
        X = x0 + (wp.float64(i0 + ib) + xoff) * dx - pos[0]
        Y = yc[j0 + jb] - pos[1]
        # rotate into the body frame
        phi[jb, ib] = polygon_signed_distance(c * X + s * Y, -s * X + c * Y, verts)


@wp.func
def rigid_velocity(x: wp.float64, y: wp.float64, pos: wp.vec3d, vel: wp.vec3d, comp: int):
    """Component comp (0: u, 1: v) of u_ref + omega x (r - r_ref)."""
    if comp == 0:
        return vel[0] - vel[2] * (y - pos[1])
    return vel[1] + vel[2] * (x - pos[0])


@wp.func
def face_gradient(p: wp.array2d(dtype=wp.float64), hy_f: wp.array(dtype=wp.float64), dx: wp.float64,
                  comp: int, J: int, I: int):
    """(grad p) on the u-face (comp 0) or v-face (comp 1) stored at (J, I)."""
    if comp == 0:
        return (p[J, I] - p[J, I - 1]) / dx
    return (p[J, I] - p[J - 1, I]) / hy_f[J]


@wp.func
def square_to_wall(x: wp.float64, y: wp.float64, pos: wp.vec3d, verts: wp.array(dtype=wp.vec2d), di: int, dj: int):
    """Whether the grid line (di, dj) through the face at (x, y) runs within 45 degrees of the wall's normal
    there: the direction from the face's nearest point on the moved polygon to the face (the gradient of
    the distance; at a corner the direction from the corner)."""
    c = wp.cos(pos[2])
    s = wp.sin(pos[2])
    X = x - pos[0]
    Y = y - pos[1]
    bx = c * X + s * Y
    by = -s * X + c * Y
    near = polygon_nearest(bx, by, verts)
    n = verts.shape[0]
    k = int(near[1])
    a = verts[k]
    b = verts[(k + 1) % n]
    t = near[2]
    nx = bx - (a[0] + t * (b[0] - a[0]))
    ny = by - (a[1] + t * (b[1] - a[1]))
    length = wp.sqrt(nx * nx + ny * ny)
    ok = False
    if length > wp.float64(0.0):
        # the normal in the grid frame, and its component along the line
        gx = c * nx - s * ny
        gy = s * nx + c * ny
        ok = wp.abs(gx * wp.float64(di) + gy * wp.float64(dj)) > wp.float64(0.7071067811865476) * length
    return ok


@wp.func
def projected(q: wp.array2d(dtype=wp.float64), p: wp.array2d(dtype=wp.float64), hy_f: wp.array(dtype=wp.float64),
              dx: wp.float64, cgrad: wp.float64, compensate: int, comp: int, J: int, I: int):
    """The predicted face value as the projection will leave it, q - cgrad (grad p) with the latest
    pressure (``compensate`` 1), or q itself (``compensate`` 0)."""
    if compensate != 0:
        return q[J, I] - cgrad * face_gradient(p, hy_f, dx, comp, J, I)
    return q[J, I]


@wp.kernel
def ib_targets(q: wp.array2d(dtype=wp.float64), phi: wp.array2d(dtype=wp.float64),
               x0: wp.float64, dx: wp.float64, xoff: wp.float64, yc: wp.array(dtype=wp.float64),
               pos: wp.vec3d, vel: wp.vec3d, comp: int, i0: int, j0: int, ni: int,
               ilo: int, ihi: int, jlo: int, jhi: int, order: int, wall_law: int, nu: wp.float64,
               verts: wp.array(dtype=wp.vec2d), p: wp.array2d(dtype=wp.float64),
               hy_f: wp.array(dtype=wp.float64), cgrad: wp.float64, compensate: int,
               nu_eff: wp.array2d(dtype=wp.float64),
               target: wp.array2d(dtype=wp.float64), state: wp.array2d(dtype=wp.int32)):
    """Direct-forcing target of each face in the box (state: 0 fluid, 1 solid, 2 interface).

    Solid faces (phi <= 0) take the rigid-body velocity. Fluid faces with a solid neighbour along a
    grid line take the linear interpolation (Fadlun et al. 2000) between the body velocity at the
    interface point (distance d found from phi along the line) and the next fluid face:
    q_f = q_b + (q_o - q_b) d / (d + h) (``order`` 1), or the quadratic through q_b, q_o and the face
    after q_o (``order`` 2); estimates from several lines are averaged. The neighbours q_o, q_oo are
    taken as the projection will leave them (``projected``: q - cgrad grad p with the latest pressure,
    ``compensate`` 1; bridge.cfd.immersed). ``wall_law`` 1 (with ``order``
    1): the wall function of a turbulent flow at high Reynolds number - for the component across the
    line (u on a vertical line, v on a horizontal one), q_f = q_b + (q_o - q_b) r with r = u(phi_f) /
    u(phi_o) on Spalding's law of the wall through q_o (``kernels.wall_law``; phi: the faces' distances
    to the wall, u_tau from |q_o - q_b| and the molecular ``nu``; r = phi_f / phi_o, the linear profile,
    when the reference face lies in the viscous sublayer), on lines that meet the wall nearly square
    (within 45 degrees of its normal, ``square_to_wall``). The component along the line, which meets
    the wall, keeps the straight line: the law of the wall is a tangential profile, and applied to the
    normal velocity of a moving deck it made its heave damping change sign. So does the
    component across a line that meets an inclined wall obliquely: there it is mostly the normal
    velocity (v on a horizontal line against the deck's 28-degree bottom panels), and the wall law on it
    let the flow through the wall at the trailing edge until the run diverged.
    ``wall_law`` 2: the same law blended with the linear profile, r = r_lin + w (r_law - r_lin), by the
    reference face's eddy viscosity against the law's own there (``nu_eff``: the flow's nu + nu_t, cells;
    w = min(1, 2 (nu_eff - nu) / nu_t,law), nu_t,law = nu (dy+/du+ - 1), ``kernels.wall_law``): where the layer
    is laminar (the SST plate's leading edge, nu_t ~ 0) the wall is no-slip and the layer can separate; where it
    is a developed turbulent layer (nu_t 0.9-1.0 of the law's at the reference face on TMR's plate) the law.
    Only faces with ilo <= I < ihi and jlo <= J < jhi are updated (boundary faces excluded);
    reads ``q`` and writes ``target``/``state`` only, so the result does not depend on order.
    """
    jb = wp.tid()
    J = j0 + jb
    for ib in range(ni):
        I = i0 + ib
        st = int(0)  # noqa: UP018 (Warp: a dynamic variable, mutated in the loop)
        tg = wp.float64(0.0)
        if ib > 0 and ib < ni - 1 and jb > 0 and jb < phi.shape[0] - 1 and I >= ilo and I < ihi \
                and J >= jlo and J < jhi:
            ph = phi[jb, ib]
            x = x0 + (wp.float64(I) + xoff) * dx
            y = yc[J]
            if ph <= wp.float64(0.0):
                st = 1
                tg = rigid_velocity(x, y, pos, vel, comp)
            else:
                acc = wp.float64(0.0)
                cnt = wp.float64(0.0)
                for k in range(4):
                    di = int(0)  # noqa: UP018 (Warp dynamic variable)
                    dj = int(0)  # noqa: UP018 (Warp dynamic variable)
                    h = wp.float64(dx)
                    if k == 0:
                        di = -1
                    elif k == 1:
                        di = 1
                    elif k == 2:
                        dj = -1
                        h = yc[J] - yc[J - 1]
                    else:
                        dj = 1
                        h = yc[J + 1] - yc[J]
                    pn = phi[jb + dj, ib + di]
                    if pn <= wp.float64(0.0):
                        d = h * ph / (ph - pn)  # distance face -> interface along the line
                        xb = x + wp.float64(di) * d
                        yb = y + wp.float64(dj) * d
                        qb = rigid_velocity(xb, yb, pos, vel, comp)
                        qo = projected(q, p, hy_f, dx, cgrad, compensate, comp, J - dj, I - di)
                        ho = h
                        if dj != 0:
                            ho = wp.abs(yc[J - dj] - yc[J])
                        if order == 2:
                            # quadratic through the wall point and the next two faces on the line
                            qoo = projected(q, p, hy_f, dx, cgrad, compensate, comp, J - 2 * dj, I - 2 * di)
                            hoo = h
                            if dj != 0:
                                hoo = wp.abs(yc[J - 2 * dj] - yc[J - dj])
                            s1 = d + ho
                            s2 = s1 + hoo
                            acc += qb * (s1 - d) * (s2 - d) / (s1 * s2) \
                                + qo * d * (s2 - d) / (s1 * hoo) - qoo * d * (s1 - d) / (s2 * hoo)
                        else:
                            r = d / (d + ho)
                            po = phi[jb - dj, ib - di]
                            # the wall function for the component across the line only (u on a vertical
                            # line, v on a horizontal one: the tangential one at a wall that the line meets
                            # square); the component along the line, towards the wall, keeps the straight line
                            tangential = (comp == 0 and dj != 0) or (comp == 1 and di != 0)
                            if wall_law != 0 and po > ph and tangential:
                                if square_to_wall(x, y, pos, verts, di, dj):
                                    r_wall = wall_law_ratio(wp.abs(qo - qb), po, ph, nu)
                                    if wall_law == 2:
                                        # blended: the wall law as far as the reference face's eddy
                                        # viscosity (nu_eff - nu) reaches the law's own there
                                        Jo = J - dj
                                        Io = I - di
                                        nuo = wp.float64(0.5) * (nu_eff[Jo, Io] + nu_eff[Jo - comp, Io - 1 + comp])
                                        law = wall_law_eddy_viscosity(wp.abs(qo - qb), po, nu)
                                        wgt = wp.float64(1.0)
                                        if law > wp.float64(0.0):
                                            wgt = wp.min(wp.max(wp.float64(2.0) * (nuo - nu) / law, wp.float64(0.0)),
                                                         wp.float64(1.0))
                                        r = r + wgt * (r_wall - r)
                                    else:
                                        r = r_wall
                            acc += qb + (qo - qb) * r
                        cnt += wp.float64(1.0)
                if cnt > wp.float64(0.0):
                    st = 2
                    tg = acc / cnt
        target[jb, ib] = tg
        state[jb, ib] = st


@wp.kernel
def ib_apply(q: wp.array2d(dtype=wp.float64), target: wp.array2d(dtype=wp.float64),
             state: wp.array2d(dtype=wp.int32), x0: wp.float64, dx: wp.float64, xoff: wp.float64,
             yc: wp.array(dtype=wp.float64), hy: wp.array(dtype=wp.float64), pos: wp.vec3d,
             comp: int, i0: int, j0: int, ni: int, slot: int, p: wp.array2d(dtype=wp.float64),
             hy_f: wp.array(dtype=wp.float64), cgrad: wp.float64, compensate: int,
             acc: wp.array(dtype=wp.float64)):
    """q = target on forced faces; acc[3 slot + comp] += momentum added (per unit density),
    acc[3 slot + 2] += its moment about pos[0:2]. ``hy`` is the face control-volume height.
    ``compensate``: the target is raised by cgrad * (grad p)_face (``hy_f``: v-face spacing), so the
    projection with factor cgrad brings the face back to the target (bridge.cfd.immersed)."""
    jb = wp.tid()
    J = j0 + jb
    mom = wp.float64(0.0)
    mz = wp.float64(0.0)
    for ib in range(ni):
        if state[jb, ib] != 0:
            I = i0 + ib
            tq = target[jb, ib]
            if compensate != 0:
                tq += cgrad * face_gradient(p, hy_f, dx, comp, J, I)
            dq = (tq - q[J, I]) * dx * hy[J]
            q[J, I] = tq
            mom += dq
            if comp == 0:
                mz -= (yc[J] - pos[1]) * dq
            else:
                mz += (x0 + (wp.float64(I) + xoff) * dx - pos[0]) * dq
    wp.atomic_add(acc, 3 * slot + comp, mom)
    wp.atomic_add(acc, 3 * slot + 2, mz)


@wp.kernel
def fill_rows(q: wp.array2d(dtype=wp.float64), value: wp.float64):
    """q[:, :] = value (row kernel)."""
    J = wp.tid()
    for I in range(q.shape[1]):
        q[J, I] = value


@wp.kernel
def tridiag_columns(r: wp.array2d(dtype=wp.float64), scale: wp.array(dtype=wp.float64),
                    lower: wp.array(dtype=wp.float64), inv_denom: wp.array2d(dtype=wp.float64),
                    cprime: wp.array2d(dtype=wp.float64),
                    block: int, row0: int):
    """Thomas algorithm along the rows (y) of ``r`` for a block of columns, in place.

    Column k solves lower[j] x[j-1] + d[j, k] x[j] + upper[j, k] x[j+1] = scale[j] r[j, k] with the
    factorisation precomputed (``cprime`` = upper / denom, ``inv_denom`` = 1 / denom); thread index
    b (+ ``row0``, the launcher's chunk offset) owns columns [b block, (b+1) block), so that each
    row of a block is a contiguous inner loop (docs/warp_cpu.md: row loops, no 2D tid)."""
    b = row0 + wp.tid()
    ny = r.shape[0]
    k0 = b * block
    k1 = wp.min(k0 + block, r.shape[1])
    for k in range(k0, k1):
        r[0, k] = scale[0] * r[0, k] * inv_denom[0, k]
    for j in range(1, ny):
        lo = lower[j]
        sj = scale[j]
        for k in range(k0, k1):
            r[j, k] = (sj * r[j, k] - lo * r[j - 1, k]) * inv_denom[j, k]
    for jj in range(1, ny):
        j = ny - 1 - jj
        for k in range(k0, k1):
            r[j, k] = r[j, k] - cprime[j, k] * r[j + 1, k]


@wp.kernel
def corner_interpolate(field: wp.array2d(dtype=wp.float64), x0: wp.float64, dx: wp.float64,
                       y_nodes: wp.array(dtype=wp.float64), px: wp.array(dtype=wp.float64),
                       py: wp.array(dtype=wp.float64), out: wp.array(dtype=wp.float64)):
    """Cubic Lagrange interpolation (4 x 4 nodes) of ``field`` on the lattice x0 + i dx (uniform) by
    ``y_nodes`` (any increasing spacing) at the points (px, py): the stencil nearest each point,
    shifted inwards at the lattice's edges (the overset coupling, ``bridge.cfd.overset``)."""
    k = wp.tid()
    ny = field.shape[0]
    nx = field.shape[1]
    sx = (px[k] - x0) / dx
    i = wp.clamp(int(wp.floor(sx)) - 1, 0, nx - 4)
    s = sx - wp.float64(i)
    one = wp.float64(1.0)
    two = wp.float64(2.0)
    three = wp.float64(3.0)
    six = wp.float64(6.0)
    wx = wp.vec4d(-(s - one) * (s - two) * (s - three) / six, s * (s - two) * (s - three) / two,
                  -s * (s - one) * (s - three) / two, s * (s - one) * (s - two) / six)
    y = py[k]
    lo = int(0)  # noqa: UP018 (a Warp variable that the loop may reassign, not a constant)
    hi = ny
    while lo < hi:   # lo = the number of nodes <= y
        mid = (lo + hi) // 2
        if y_nodes[mid] <= y:
            lo = mid + 1
        else:
            hi = mid
    j = wp.clamp(lo - 2, 0, ny - 4)
    y0 = y_nodes[j]
    y1 = y_nodes[j + 1]
    y2 = y_nodes[j + 2]
    y3 = y_nodes[j + 3]
    wy = wp.vec4d((y - y1) * (y - y2) * (y - y3) / ((y0 - y1) * (y0 - y2) * (y0 - y3)),
                  (y - y0) * (y - y2) * (y - y3) / ((y1 - y0) * (y1 - y2) * (y1 - y3)),
                  (y - y0) * (y - y1) * (y - y3) / ((y2 - y0) * (y2 - y1) * (y2 - y3)),
                  (y - y0) * (y - y1) * (y - y2) / ((y3 - y0) * (y3 - y1) * (y3 - y2)))
    acc = wp.float64(0.0)
    for a in range(4):
        row = wx[0] * field[j + a, i] + wx[1] * field[j + a, i + 1] + wx[2] * field[j + a, i + 2] \
            + wx[3] * field[j + a, i + 3]
        acc += wy[a] * row
    out[k] = acc
