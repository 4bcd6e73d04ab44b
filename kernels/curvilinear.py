"""Warp kernels of the body-fitted solver (bridge/cfd/curvilinear.py): the line solves of its implicit
diffusion, one thread per grid line, and its explicit stencils (``advection``, ``diffusion_parts``,
``cell_gradient``), one thread per ring (storage [j, i]: ring j from the wall, i around the body, periodic).

``line_solve_rings``: along each line i, (I + diag - c L_j) x = r with L_j the ring-to-ring diffusion and
  upwind advection (L_j x)_j = k_lo[j] (x[j-1] - x[j]) + k_hi[j] (x[j+1] - x[j]) (k: c nu alpha / area and
  the upwind fluxes' c F / area, already times c) and ``diag`` what the advection's conservative form adds to
  the diagonal; x[-1] and x[nj] zero (the boundary values are in r); on ring 0 the wall face's second-order
  gradient w0 (x0 - x_w) + w1 (x1 - x_w) replaces k_lo (x0 - x_w).
``line_solve_around``: along each ring j, (I - c L_i) x = r with L_i the diffusion around the ring,
  periodic: (L_i x)_i = k_m[i] (x[i-1] - x[i]) + k_p[i] (x[i+1] - x[i]); a cyclic tridiagonal system,
  solved by the Thomas algorithm with the Sherman-Morrison correction.
``wall_friction``: the friction velocity of each wall face from its first cell on Spalding's law (the SST
  model's wall function, bridge/cfd/curvilinear_sst.py), one thread per face.
"""

import warp as wp

from kernels.wall_law import friction_uplus


@wp.kernel
def line_solve_rings(k_lo: wp.array2d(dtype=wp.float64), k_hi: wp.array2d(dtype=wp.float64),
                     diag: wp.array2d(dtype=wp.float64),
                     w0: wp.array(dtype=wp.float64), w1: wp.array(dtype=wp.float64),
                     r: wp.array2d(dtype=wp.float64), nj: int,
                     cp: wp.array2d(dtype=wp.float64), x: wp.array2d(dtype=wp.float64)):
    i = wp.tid()
    one = wp.float64(1.0)
    # ring 0: diagonal 1 + k_hi + k_lo w0 + diag, upper -(k_hi - k_lo w1)
    d = one + k_hi[0, i] + k_lo[0, i] * w0[i] + diag[0, i]
    up = -(k_hi[0, i] - k_lo[0, i] * w1[i])
    cp[0, i] = up / d
    x[0, i] = r[0, i] / d
    for j in range(1, nj):
        lo = -k_lo[j, i]
        dj = one + k_lo[j, i] + k_hi[j, i] + diag[j, i]
        m = dj - lo * cp[j - 1, i]
        cp[j, i] = -k_hi[j, i] / m
        x[j, i] = (r[j, i] - lo * x[j - 1, i]) / m
    for jj in range(nj - 1):
        j = nj - 2 - jj
        x[j, i] = x[j, i] - cp[j, i] * x[j + 1, i]


@wp.kernel
def line_solve_around(k_m: wp.array2d(dtype=wp.float64), k_p: wp.array2d(dtype=wp.float64),
                      r: wp.array2d(dtype=wp.float64), ni: int,
                      cp: wp.array2d(dtype=wp.float64), y: wp.array2d(dtype=wp.float64),
                      z: wp.array2d(dtype=wp.float64), x: wp.array2d(dtype=wp.float64)):
    j = wp.tid()
    one = wp.float64(1.0)
    # A = tridiag(-k_m, 1 + k_m + k_p, -k_p) with corners A[0, n-1] = -k_m[0], A[n-1, 0] = -k_p[n-1].
    # Sherman-Morrison: A = B + u v^T, u = (gamma, 0, ..., 0, A[n-1, 0]), v = (1, 0, ..., 0, A[0, n-1] / gamma)
    n = ni
    a0 = -k_m[j, 0]           # A[0, n-1]
    cn = -k_p[j, n - 1]       # A[n-1, 0]
    b0 = one + k_m[j, 0] + k_p[j, 0]
    gamma = -b0
    # solve B y = r and B z = u with B's first and last diagonals modified
    d = b0 - gamma
    cp[j, 0] = -k_p[j, 0] / d
    y[j, 0] = r[j, 0] / d
    z[j, 0] = gamma / d
    for i in range(1, n):
        lo = -k_m[j, i]
        di = one + k_m[j, i] + k_p[j, i]
        if i == n - 1:
            di = di - cn * a0 / gamma
        m = di - lo * cp[j, i - 1]
        cp[j, i] = -k_p[j, i] / m
        y[j, i] = (r[j, i] - lo * y[j, i - 1]) / m
        u_i = wp.float64(0.0)
        if i == n - 1:
            u_i = cn
        z[j, i] = (u_i - lo * z[j, i - 1]) / m
    for ii in range(n - 1):
        i = n - 2 - ii
        y[j, i] = y[j, i] - cp[j, i] * y[j, i + 1]
        z[j, i] = z[j, i] - cp[j, i] * z[j, i + 1]
    vy = y[j, 0] + a0 / gamma * y[j, n - 1]
    vz = z[j, 0] + a0 / gamma * z[j, n - 1]
    f = vy / (one + vz)
    for i in range(n):
        x[j, i] = y[j, i] - f * z[j, i]


# --- the explicit stencils (bridge/cfd/curvilinear.py's module doc), one thread per ring j, the cells of the ring
# --- in a loop (one row per thread: WARP_CPU.md); a cell computes its four faces itself (each face twice)

@wp.func
def _limited(qu: wp.float64, qd: wp.float64, quu: wp.float64):
    """Face value from the upwind cell qu towards the downwind qd, limited by the second upwind quu (van Leer)."""
    dq = qd - qu
    r = wp.float64(0.0)
    if wp.abs(dq) > wp.float64(1e-300):
        r = (qu - quu) / dq
    return qu + wp.float64(0.5) * ((r + wp.abs(r)) / (wp.float64(1.0) + wp.abs(r))) * dq


@wp.func
def _face_j(ext: wp.array2d(dtype=wp.float64), Fj: wp.array2d(dtype=wp.float64),
            implicit_j: wp.array2d(dtype=wp.int32), correct: int, f: int, i: int):
    """The advective flux through j-face f (between rings f-1 and f; ext row r is ring r-1); the wall face's none;
    with ``correct`` an implicit face's van Leer flux less the upwind one (``advection``)."""
    F = Fj[f, i]
    out = wp.float64(0.0)
    if f > 0:
        limited = wp.float64(0.0)
        if F > wp.float64(0.0):
            limited = _limited(ext[f, i], ext[f + 1, i], ext[f - 1, i])
        else:
            limited = _limited(ext[f + 1, i], ext[f, i], ext[f + 2, i])
        if correct != 0 and implicit_j[f, i] != 0:
            upwinded = ext[f + 1, i]
            if F > wp.float64(0.0):
                upwinded = ext[f, i]
            out = F * (limited - upwinded)
        else:
            out = F * limited
    return out


@wp.func
def _face_i(ext: wp.array2d(dtype=wp.float64), Fi: wp.array2d(dtype=wp.float64), ni: int, j: int, i: int):
    """The advective flux through i-face i of ring j (between cells i-1 and i)."""
    r = j + 1
    F = Fi[j, i]
    im1 = i - 1
    if im1 < 0:
        im1 = im1 + ni
    out = wp.float64(0.0)
    if F > wp.float64(0.0):
        im2 = im1 - 1
        if im2 < 0:
            im2 = im2 + ni
        out = F * _limited(ext[r, im1], ext[r, i], ext[r, im2])
    else:
        ip1 = i + 1
        if ip1 == ni:
            ip1 = 0
        out = F * _limited(ext[r, i], ext[r, im1], ext[r, ip1])
    return out


@wp.kernel
def advection(ext: wp.array2d(dtype=wp.float64), Fi: wp.array2d(dtype=wp.float64),
              Fj: wp.array2d(dtype=wp.float64), implicit_j: wp.array2d(dtype=wp.int32), correct: int,
              area: wp.array2d(dtype=wp.float64), ni: int, out: wp.array2d(dtype=wp.float64)):
    """div(q (u - u_g)) per cell area: ``ext`` (nj + 3, ni) is q with the wall's reflection (row 0) and two ghost
    rings (rows nj + 1, nj + 2); Fi, Fj the relative fluxes; van Leer's limited upwind face values along the grid
    lines; with ``correct`` 1, on the implicit j-faces (``implicit_j``) van Leer's less first-order upwind's
    (the deferred correction: a line solve carries the upwind part)."""
    j = wp.tid()
    f_m = _face_i(ext, Fi, ni, j, 0)          # the cell's minus i-face, carried from the cell before
    for i in range(ni):
        ip1 = i + 1
        if ip1 == ni:
            ip1 = 0
        f_p = _face_i(ext, Fi, ni, j, ip1)
        out[j, i] = (f_p - f_m + _face_j(ext, Fj, implicit_j, correct, j + 1, i)
                     - _face_j(ext, Fj, implicit_j, correct, j, i)) / area[j, i]
        f_m = f_p


@wp.func
def _node(q: wp.array2d(dtype=wp.float64), ghost: wp.array(dtype=wp.float64), wall_node: wp.array(dtype=wp.float64),
          nj: int, ni: int, j: int, i: int):
    """q at node (j, i) (0 <= i < ni): the wall's on ring 0, else the mean of the four cells around (the ghost
    ring beyond nj)."""
    out = wp.float64(0.0)
    if j == 0:
        out = wall_node[i]
    else:
        im1 = i - 1
        if im1 < 0:
            im1 = ni - 1
        if j == nj:
            out = wp.float64(0.25) * (q[j - 1, i] + q[j - 1, im1] + ghost[i] + ghost[im1])
        else:
            out = wp.float64(0.25) * (q[j - 1, i] + q[j - 1, im1] + q[j, i] + q[j, im1])
    return out


@wp.kernel
def diffusion_parts(q: wp.array2d(dtype=wp.float64), gam_i: wp.array2d(dtype=wp.float64),
                    gam_j: wp.array2d(dtype=wp.float64), wall_face: wp.array(dtype=wp.float64),
                    wall_node: wp.array(dtype=wp.float64), ghost: wp.array(dtype=wp.float64),
                    w0: wp.array(dtype=wp.float64), w1: wp.array(dtype=wp.float64),
                    alpha_i: wp.array2d(dtype=wp.float64), beta_i: wp.array2d(dtype=wp.float64),
                    alpha_j: wp.array2d(dtype=wp.float64), beta_j: wp.array2d(dtype=wp.float64),
                    area: wp.array2d(dtype=wp.float64), nj: int, ni: int,
                    cross: wp.array2d(dtype=wp.float64), around: wp.array2d(dtype=wp.float64),
                    rings: wp.array2d(dtype=wp.float64)):
    """div(Gamma grad q) per cell area in three parts (the cross terms, the alpha terms around the ring and across
    the rings): i-faces alpha (q_i - q_{i-1}) + beta (node (j+1, i) - node (j, i)), j-faces alpha (above - below)
    + beta (node (j, i+1) - node (j, i)), the wall face's normal gradient w0 (q0 - q_w) + w1 (q1 - q_w), the
    outer face's with the ghost ring."""
    j = wp.tid()
    # the minus i-face's fluxes and the cell's two minus-side nodes, carried from the cell before
    n00 = _node(q, ghost, wall_node, nj, ni, j, 0)
    n10 = _node(q, ghost, wall_node, nj, ni, j + 1, 0)
    fn_m = gam_i[j, 0] * alpha_i[j, 0] * (q[j, 0] - q[j, ni - 1])
    fc_m = gam_i[j, 0] * beta_i[j, 0] * (n10 - n00)
    for i in range(ni):
        ip1 = i + 1
        if ip1 == ni:
            ip1 = 0
        n01 = _node(q, ghost, wall_node, nj, ni, j, ip1)
        n11 = _node(q, ghost, wall_node, nj, ni, j + 1, ip1)
        fn_p = gam_i[j, ip1] * alpha_i[j, ip1] * (q[j, ip1] - q[j, i])
        fc_p = gam_i[j, ip1] * beta_i[j, ip1] * (n11 - n01)
        gc_lo = gam_j[j, i] * beta_j[j, i] * (n01 - n00)
        gc_hi = gam_j[j + 1, i] * beta_j[j + 1, i] * (n11 - n10)
        gn_lo = wp.float64(0.0)
        if j == 0:
            gn_lo = alpha_j[0, i] * (w0[i] * (q[0, i] - wall_face[i]) + w1[i] * (q[1, i] - wall_face[i]))
        else:
            gn_lo = alpha_j[j, i] * (q[j, i] - q[j - 1, i])
        gn_lo = gn_lo * gam_j[j, i]
        above = wp.float64(0.0)
        if j == nj - 1:
            above = ghost[i]
        else:
            above = q[j + 1, i]
        gn_hi = alpha_j[j + 1, i] * (above - q[j, i]) * gam_j[j + 1, i]
        a = area[j, i]
        cross[j, i] = (fc_p - fc_m + gc_hi - gc_lo) / a
        around[j, i] = (fn_p - fn_m) / a
        rings[j, i] = (gn_hi - gn_lo) / a
        fn_m = fn_p
        fc_m = fc_p
        n00 = n01
        n10 = n11


@wp.kernel
def cell_gradient(q: wp.array2d(dtype=wp.float64), wall_face: wp.array(dtype=wp.float64),
                  outer_face: wp.array(dtype=wp.float64), six: wp.array2d(dtype=wp.float64),
                  siy: wp.array2d(dtype=wp.float64), sjx: wp.array2d(dtype=wp.float64),
                  sjy: wp.array2d(dtype=wp.float64), area: wp.array2d(dtype=wp.float64), nj: int, ni: int,
                  gx: wp.array2d(dtype=wp.float64), gy: wp.array2d(dtype=wp.float64)):
    """grad q at the cell centres by Green-Gauss: interior faces the mean of their two cells, the wall and outer
    faces the values given."""
    j = wp.tid()
    half = wp.float64(0.5)
    qm = half * (q[j, 0] + q[j, ni - 1])     # the minus i-face's value, carried from the cell before
    for i in range(ni):
        ip1 = i + 1
        if ip1 == ni:
            ip1 = 0
        qp = half * (q[j, ip1] + q[j, i])
        qlo = wp.float64(0.0)
        if j == 0:
            qlo = wall_face[i]
        else:
            qlo = half * (q[j, i] + q[j - 1, i])
        qhi = wp.float64(0.0)
        if j == nj - 1:
            qhi = outer_face[i]
        else:
            qhi = half * (q[j + 1, i] + q[j, i])
        a = area[j, i]
        gx[j, i] = (qp * six[j, ip1] - qm * six[j, i] + qhi * sjx[j + 1, i] - qlo * sjx[j, i]) / a
        gy[j, i] = (qp * siy[j, ip1] - qm * siy[j, i] + qhi * sjy[j + 1, i] - qlo * sjy[j, i]) / a
        qm = qp


@wp.kernel
def wall_friction(speed: wp.array(dtype=wp.float64), d: wp.array(dtype=wp.float64), nu: wp.float64,
                  u_tau: wp.array(dtype=wp.float64)):
    """u_tau of each wall face from its first cell's speed relative to the wall at the distance d on Spalding's
    law (kernels/wall_law.py): speed / u+, u+ the root of u+ y+(u+) = speed d / nu; zero where the cell is at
    rest relative to the wall."""
    i = wp.tid()
    s = speed[i]
    out = wp.float64(0.0)
    if s > wp.float64(0.0) and d[i] > wp.float64(0.0):
        up = friction_uplus(s * d[i] / nu)
        if up > wp.float64(0.0):
            out = s / up
    u_tau[i] = out
