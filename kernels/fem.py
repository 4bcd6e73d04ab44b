"""Warp kernels of the 3D frame finite-element model (thesis chapter 3): two-node element matrices.

Only element maths lives here (``@wp.func``) plus one thin ``@wp.kernel`` that loads an element,
calls the functions and stores its three 12x12 global matrices; ``bridge.structure.elements`` launches
it and ``bridge.structure.assembly`` scatters the results into scipy.sparse matrices.

Element DOFs per node (local and global alike): u_x, u_y, u_z, theta_x, theta_y, theta_z; node a then b.
Local frame: e1 from node a to node b; e3 = normalise(e1 x v), e2 = e3 x e1 with v the element's
orientation vector (a vector in the local 1-2 plane). Global matrix = T^T K_local T with
T = diag(R, R, R, R), R = [e1; e2; e3] (rows).

Per-element properties (``props[e, :]``, float64), see ``bridge.structure.elements.PROP_*``:
  0 EA, 1 EI_2 (bending with deflection along local e2, i.e. about e3), 2 EI_3 (deflection along e3),
  3 GJ, 4 mass per length m, 5 rotary inertia per length for e2-deflection (rho I about e3),
  6 rotary inertia for e3-deflection, 7 polar mass moment per length, 8 axial force N (tension > 0),
  9 kind (0 = Bernoulli-Euler beam, 1 = cable/truss: translations only, no bending).

Beam (kind 0): Hermite cubic bending, linear axial/torsion; consistent mass with rotary inertia
(Przemieniecki 1968, ch. 11; Cook et al., Concepts and Applications of FEA, 4th ed., 16.3) and the
consistent geometric stiffness of an axial force N (Przemieniecki; Cook 18.4) in both bending planes.
No Wagner (torsional) term in the geometric stiffness.
Cable (kind 1, 2-node truss): EA/L axially, string geometric stiffness N/L on both transverse
translations (linear shape functions), consistent linear translational mass, nothing on rotations:
a cable with N = 0 has exactly zero transverse stiffness.
"""

import warp as wp

KIND_BEAM = 0
KIND_CABLE = 1
N_PROPS = 10

# Keep loops as loops: unrolling the 12x12 block loops tripled the compile time for no run-time gain.
wp.set_module_options({"max_unroll": 1})


@wp.func
def put2(mat: wp.array3d(dtype=wp.float64), e: int, d0: int, d1: int, c: wp.float64,
         diag: wp.float64, off: wp.float64):
    """mat[e] += c [[diag, off], [off, diag]] on DOFs (d0, d1)."""
    mat[e, d0, d0] = mat[e, d0, d0] + c * diag
    mat[e, d1, d1] = mat[e, d1, d1] + c * diag
    mat[e, d0, d1] = mat[e, d0, d1] + c * off
    mat[e, d1, d0] = mat[e, d1, d0] + c * off


@wp.func
def put4(mat: wp.array3d(dtype=wp.float64), e: int, d0: int, d1: int, d2: int, d3: int,
         s: wp.float64, c: wp.float64,
         k00: wp.float64, k01: wp.float64, k02: wp.float64, k03: wp.float64, k11: wp.float64,
         k12: wp.float64, k13: wp.float64, k22: wp.float64, k23: wp.float64, k33: wp.float64):
    """mat[e] += c K on DOFs (w_a, theta_a, w_b, theta_b) = (d0, d1, d2, d3), K symmetric given by its
    upper triangle.  s = -1 flips the displacement-rotation couplings (deflection along e3, where
    theta_2 = -dw/dx), s = +1 for deflection along e2 (theta_3 = +dv/dx)."""
    mat[e, d0, d0] = mat[e, d0, d0] + c * k00
    mat[e, d1, d1] = mat[e, d1, d1] + c * k11
    mat[e, d2, d2] = mat[e, d2, d2] + c * k22
    mat[e, d3, d3] = mat[e, d3, d3] + c * k33
    v01 = c * s * k01
    v02 = c * k02
    v03 = c * s * k03
    v12 = c * s * k12
    v13 = c * k13
    v23 = c * s * k23
    mat[e, d0, d1] = mat[e, d0, d1] + v01
    mat[e, d1, d0] = mat[e, d1, d0] + v01
    mat[e, d0, d2] = mat[e, d0, d2] + v02
    mat[e, d2, d0] = mat[e, d2, d0] + v02
    mat[e, d0, d3] = mat[e, d0, d3] + v03
    mat[e, d3, d0] = mat[e, d3, d0] + v03
    mat[e, d1, d2] = mat[e, d1, d2] + v12
    mat[e, d2, d1] = mat[e, d2, d1] + v12
    mat[e, d1, d3] = mat[e, d1, d3] + v13
    mat[e, d3, d1] = mat[e, d3, d1] + v13
    mat[e, d2, d3] = mat[e, d2, d3] + v23
    mat[e, d3, d2] = mat[e, d3, d2] + v23


@wp.func
def hermite_stiffness(mat: wp.array3d(dtype=wp.float64), e: int, d0: int, d1: int, d2: int, d3: int,
                      s: wp.float64, ei: wp.float64, L: wp.float64):
    """Bernoulli-Euler bending stiffness EI/L^3 [12, 6L, -12, 6L; 4L^2, -6L, 2L^2; 12, -6L; 4L^2]."""
    put4(mat, e, d0, d1, d2, d3, s, ei / (L * L * L),
         wp.float64(12.0), wp.float64(6.0) * L, wp.float64(-12.0), wp.float64(6.0) * L,
         wp.float64(4.0) * L * L, wp.float64(-6.0) * L, wp.float64(2.0) * L * L,
         wp.float64(12.0), wp.float64(-6.0) * L, wp.float64(4.0) * L * L)


@wp.func
def hermite_mass(mat: wp.array3d(dtype=wp.float64), e: int, d0: int, d1: int, d2: int, d3: int,
                 s: wp.float64, m: wp.float64, L: wp.float64):
    """Consistent translational mass of the Hermite cubic: mL/420 [156, 22L, 54, -13L; 4L^2, 13L,
    -3L^2; 156, -22L; 4L^2]."""
    put4(mat, e, d0, d1, d2, d3, s, m * L / wp.float64(420.0),
         wp.float64(156.0), wp.float64(22.0) * L, wp.float64(54.0), wp.float64(-13.0) * L,
         wp.float64(4.0) * L * L, wp.float64(13.0) * L, wp.float64(-3.0) * L * L,
         wp.float64(156.0), wp.float64(-22.0) * L, wp.float64(4.0) * L * L)


@wp.func
def slope_pattern(mat: wp.array3d(dtype=wp.float64), e: int, d0: int, d1: int, d2: int, d3: int,
                  s: wp.float64, c: wp.float64, L: wp.float64):
    """c/(30L) [36, 3L, -36, 3L; 4L^2, -3L, -L^2; 36, -3L; 4L^2] = c int N'^T N' dx for the Hermite
    cubic: the geometric stiffness (c = N) and the rotary inertia (c = rho I)."""
    put4(mat, e, d0, d1, d2, d3, s, c / (wp.float64(30.0) * L),
         wp.float64(36.0), wp.float64(3.0) * L, wp.float64(-36.0), wp.float64(3.0) * L,
         wp.float64(4.0) * L * L, wp.float64(-3.0) * L, wp.float64(-1.0) * L * L,
         wp.float64(36.0), wp.float64(-3.0) * L, wp.float64(4.0) * L * L)


@wp.func
def local_stiffness(mat: wp.array3d(dtype=wp.float64), e: int, p: wp.array2d(dtype=wp.float64),
                    L: wp.float64):
    """Elastic stiffness in the local frame (added to mat[e], which the caller zeroes)."""
    one = wp.float64(1.0)
    put2(mat, e, 0, 6, p[e, 0] / L, one, -one)
    if p[e, 9] < wp.float64(0.5):  # beam
        put2(mat, e, 3, 9, p[e, 3] / L, one, -one)
        hermite_stiffness(mat, e, 1, 5, 7, 11, one, p[e, 1], L)
        hermite_stiffness(mat, e, 2, 4, 8, 10, -one, p[e, 2], L)


@wp.func
def local_mass(mat: wp.array3d(dtype=wp.float64), e: int, p: wp.array2d(dtype=wp.float64),
               L: wp.float64):
    """Consistent mass in the local frame (added to mat[e])."""
    one = wp.float64(1.0)
    sixth = L / wp.float64(6.0)
    m = p[e, 4]
    put2(mat, e, 0, 6, m * sixth, wp.float64(2.0), one)
    if p[e, 9] < wp.float64(0.5):  # beam: Hermite translations, rotary and torsional inertia
        put2(mat, e, 3, 9, p[e, 7] * sixth, wp.float64(2.0), one)
        hermite_mass(mat, e, 1, 5, 7, 11, one, m, L)
        hermite_mass(mat, e, 2, 4, 8, 10, -one, m, L)
        slope_pattern(mat, e, 1, 5, 7, 11, one, p[e, 5], L)
        slope_pattern(mat, e, 2, 4, 8, 10, -one, p[e, 6], L)
    else:  # cable: linear shape functions on all three translations
        put2(mat, e, 1, 7, m * sixth, wp.float64(2.0), one)
        put2(mat, e, 2, 8, m * sixth, wp.float64(2.0), one)


@wp.func
def local_geometric(mat: wp.array3d(dtype=wp.float64), e: int, p: wp.array2d(dtype=wp.float64),
                    L: wp.float64):
    """Geometric stiffness of the axial force N = p[e, 8] (tension > 0) in the local frame."""
    one = wp.float64(1.0)
    n = p[e, 8]
    if p[e, 9] < wp.float64(0.5):
        slope_pattern(mat, e, 1, 5, 7, 11, one, n, L)
        slope_pattern(mat, e, 2, 4, 8, 10, -one, n, L)
    else:  # string: N/L [1, -1; -1, 1] on both transverse translations
        put2(mat, e, 1, 7, n / L, one, -one)
        put2(mat, e, 2, 8, n / L, one, -one)


@wp.func
def local_frame(xa: wp.vec3d, xb: wp.vec3d, v: wp.vec3d):
    """Rotation R (rows e1, e2, e3: local = R global) of the element from a to b with orientation v."""
    d = xb - xa
    e1 = wp.normalize(d)
    e3 = wp.normalize(wp.cross(e1, v))
    e2 = wp.cross(e3, e1)
    return wp.mat33d(e1[0], e1[1], e1[2], e2[0], e2[1], e2[2], e3[0], e3[1], e3[2])


@wp.func
def zero_element(mat: wp.array3d(dtype=wp.float64), e: int):
    for i in range(12):
        for j in range(12):
            mat[e, i, j] = wp.float64(0.0)


@wp.func
def rotate_to_global(R: wp.mat33d, loc: wp.array3d(dtype=wp.float64), out: wp.array3d(dtype=wp.float64),
                     e: int):
    """out[e] = T^T loc[e] T, block by 3x3 block: out_ab = R^T loc_ab R."""
    Rt = wp.transpose(R)
    for a in range(4):
        for b in range(4):
            blk = wp.mat33d(
                loc[e, 3 * a, 3 * b], loc[e, 3 * a, 3 * b + 1], loc[e, 3 * a, 3 * b + 2],
                loc[e, 3 * a + 1, 3 * b], loc[e, 3 * a + 1, 3 * b + 1], loc[e, 3 * a + 1, 3 * b + 2],
                loc[e, 3 * a + 2, 3 * b], loc[e, 3 * a + 2, 3 * b + 1], loc[e, 3 * a + 2, 3 * b + 2])
            g = Rt * blk * R
            for i in range(3):
                for j in range(3):
                    out[e, 3 * a + i, 3 * b + j] = g[i, j]


@wp.kernel
def element_matrices(xa: wp.array(dtype=wp.vec3d), xb: wp.array(dtype=wp.vec3d),
                     orient: wp.array(dtype=wp.vec3d), props: wp.array2d(dtype=wp.float64),
                     scratch: wp.array3d(dtype=wp.float64), k_out: wp.array3d(dtype=wp.float64),
                     m_out: wp.array3d(dtype=wp.float64), g_out: wp.array3d(dtype=wp.float64)):
    """Global elastic stiffness, consistent mass and geometric stiffness of element e (one thread each).
    ``scratch`` (same shape as the outputs) holds the local matrices; all four arrays are overwritten."""
    e = wp.tid()
    R = local_frame(xa[e], xb[e], orient[e])
    L = wp.length(xb[e] - xa[e])
    zero_element(scratch, e)
    local_stiffness(scratch, e, props, L)
    rotate_to_global(R, scratch, k_out, e)
    zero_element(scratch, e)
    local_mass(scratch, e, props, L)
    rotate_to_global(R, scratch, m_out, e)
    zero_element(scratch, e)
    local_geometric(scratch, e, props, L)
    rotate_to_global(R, scratch, g_out, e)
