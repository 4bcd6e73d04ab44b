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

from kernels.cfd import polygon_signed_distance, upwind_flux


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
    of column I (zeros for a fixed grid)."""
    J = row0 + wp.tid()
    half = wp.float64(0.5)
    one = wp.float64(1.0)
    idx = one / dx
    ihc = one / hy_c[J]
    gx = gx_c[J]
    # y-direction spacings of the faces below (J) and above (J + 1) the row
    rm_lo = hy_f[J] / hy_f[J - 1]
    rp_lo = hy_f[J] / hy_f[J + 1]
    w_lo = half * hy_c[J - 1] / hy_f[J]
    rm_hi = hy_f[J + 1] / hy_f[J]
    rp_hi = hy_f[J + 1] / hy_f[J + 2]
    w_hi = half * hy_c[J] / hy_f[J + 1]
    # the x-flux through the left face of the first cell, then carried along the row
    I = i_lo
    fl = upwind_flux(u[J, I] - gx, q[J, I - 2], q[J, I - 1], q[J, I], q[J, I + 1], one, one, half, scheme) \
        - half * (gam[J, I - 1] + gam[J, I]) * (q[J, I] - q[J, I - 1]) * idx
    for I in range(i_lo, i_hi):
        fr = upwind_flux(u[J, I + 1] - gx, q[J, I - 1], q[J, I], q[J, I + 1], q[J, I + 2], one, one, half, scheme) \
            - half * (gam[J, I] + gam[J, I + 1]) * (q[J, I + 1] - q[J, I]) * idx
        gy = gy_c[I]
        fb = upwind_flux(v[J, I] - gy, q[J - 2, I], q[J - 1, I], q[J, I], q[J + 1, I], rm_lo, rp_lo, w_lo, scheme) \
            - half * (gam[J - 1, I] + gam[J, I]) * (q[J, I] - q[J - 1, I]) / hy_f[J]
        ft = upwind_flux(v[J + 1, I] - gy, q[J - 1, I], q[J, I], q[J + 1, I], q[J + 2, I], rm_hi, rp_hi, w_hi,
                         scheme) \
            - half * (gam[J, I] + gam[J + 1, I]) * (q[J + 1, I] - q[J, I]) / hy_f[J + 1]
        rhs = -(fr - fl) * idx - (ft - fb) * ihc + s_e[J, I]
        out[J, I] = (a * q0[J, I] + b * (q[J, I] + dt * rhs)) / (one + b * dt * s_i[J, I])
        fl = fr


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

