"""Warp kernels of the body-fitted solver (bridge/cfd/curvilinear.py): the line solves of its implicit
diffusion, one thread per grid line (storage [j, i]: ring j from the wall, i around the body, periodic).

``line_solve_rings``: along each line i, (I + diag - c L_j) x = r with L_j the ring-to-ring diffusion and
  upwind advection (L_j x)_j = k_lo[j] (x[j-1] - x[j]) + k_hi[j] (x[j+1] - x[j]) (k: c nu alpha / area and
  the upwind fluxes' c F / area, already times c) and ``diag`` what the advection's conservative form adds to
  the diagonal; x[-1] and x[nj] zero (the boundary values are in r); on ring 0 the wall face's second-order
  gradient w0 (x0 - x_w) + w1 (x1 - x_w) replaces k_lo (x0 - x_w).
``line_solve_around``: along each ring j, (I - c L_i) x = r with L_i the diffusion around the ring,
  periodic: (L_i x)_i = k_m[i] (x[i-1] - x[i]) + k_p[i] (x[i+1] - x[i]); a cyclic tridiagonal system,
  solved by the Thomas algorithm with the Sherman-Morrison correction.
"""

import warp as wp


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
