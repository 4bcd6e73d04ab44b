"""Direct-forcing immersed boundary for a rigid polygon with prescribed motion, and its force.

Method (Fadlun, Verzicco, Orlandi and Mohd-Yusof 2000, J. Comput. Phys. 161): after each predictor
stage the velocity is set directly on the faces (no pressure-operator change, so the fast Poisson
solver still applies): faces inside the polygon take the rigid-body velocity; fluid faces next to the
interface take the linear interpolation, along the grid line, between the body velocity at the
interface point and the next fluid face (``order=1``; ``order=2``: the quadratic through the interface
point and the next two faces on the line). The interface distance along the line comes from the signed
distance to the polygon, so the boundary is sharp (second order in the interface position) rather
than a staircase. Faces are re-classified every step at the body pose of the new time level.

Pressure compensation (with the "full" pressure form of ``time_stepping``): a forced face is set to
target + c G p (c = b dt of the stage, p the latest pressure), so that the projection that follows,
u = u* - c G phi, leaves it at the target once phi = p. Setting it to the bare target instead undoes
the previous projection's correction on every forced face each stage; that reset is a source
D(G phi) in the cut cells that does not shrink with dt or h and biased the pressure field near the
body: DFG 2D-1 pressure difference 0.141-0.143 at D/16-D/48 against 0.1175, with c_D nearly right.
With the compensation: 0.1160 (D/16), 0.1174 (D/32). At a steady state the forced faces then hold
the target exactly and the pressure at fluid faces is decoupled from the forced ones, as with a
Neumann condition on the interface. The target itself is interpolated from the neighbouring faces as
the projection will leave them, q* - c G p (``kernels.cfd.projected``): the predicted q* lacks the
pressure gradient (the "full" form), so interpolating from it put the forced face on a line through a
neighbour that the projection then moves by c G p, a wall-profile error of order dt. With the
estimate the error is of order dt^2, as in the incremental form; DFG 2D-2's lift amplitude rose by
1.8 % at D/16 and 0.8 % at D/32 (docs/validation.md).

Mass (``close_targets``): a cell whose four faces are all forced (solid faces and interface faces
together) gets no free face for the projection to adjust, and the interpolated interface targets
do not in general add up to zero flux there. Left alone, the projection carried the mismatch through
the body (solid faces at 1-2 % of the mean flow in DFG 2D-1, not shrinking with h), the pressure inside
the body grew by a fixed amount every step (linearly, without bound), and a moving body, whose
cells change class as it moves, felt that pressure as step-to-step force noise (heaving cylinder,
D/16: the second difference of the lift 0.90 rms against 0.05 with the fix). So after interpolation
the interface targets get the least change (sum of squares) that makes every such cell
divergence-free: delta = -A^T (A A^T)^-1 r, A the flux of each interface face into the cells, r the
cells' net flux. The fluid then sees an impermeable body and the interior pressure stays bounded; the
first harmonic of the forces on a heaving body moved by < 0.6 %, DFG 2D-1 c_D by +0.03 % and dp by
-0.1 % at D/48 (docs/validation.md).

Force (per unit length, ``rho`` times the kinematic quantities): the momentum the forcing adds to the
grid fluid over a step, M (each stage's contribution weighted by how it enters the final stage), is
the impulse of the body on the fluid, real and virtual (the fluid inside the body). The virtual fluid
moves rigidly, so its momentum is rho A v_c (v_c: centroid velocity). Hence, on the body,
  F = -rho M / dt + rho A (v_c^{n+1} - v_c^n) / dt,
  M_z = -rho M_z,forcing / dt + rho [I_c alpha + (r_c - r_O) x A a_c]   (about the body reference O),
the integrated-forcing force with the internal-fluid correction of Uhlmann (2005, J. Comput. Phys.
209) / Feng and Michaelides; exact for a moving body as far as the virtual fluid moves rigidly.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
import warp as wp
from scipy.sparse.linalg import factorized

from kernels import cfd as _k

from .bodies import Polygon
from .grids import GHOST, CartesianGrid
from .precision import WP_DTYPE

__all__ = ["ImmersedBody"]


class ImmersedBody:
    """A rigid polygon on a grid: classifies faces, applies the forcing, returns forces.

    ``apply`` mutates the predicted velocity in place. ``margin`` cells surround the body's box;
    ``substeps``: of the time scheme (the Runge-Kutta stages; the forcing impulse is kept per substep).
    """

    def __init__(self, polygon: Polygon, motion, grid: CartesianGrid, launcher, margin: int = 3,
                 order: int = 1, substeps: int = 2):
        if margin < 2:
            raise ValueError(f"margin: must be >= 2 cells, got {margin}")
        if order not in (1, 2):
            raise ValueError(f"order: interpolation order 1 or 2, got {order}")
        self.order = order
        self.wall_law = None   # molecular nu of the wall function (set_wall_function); None: no wall function
        self._nu_eff = None    # nu + nu_t (cell storage) that blends the wall function (set_wall_function)
        self.polygon, self.motion, self.grid, self.L = polygon, motion, grid, launcher
        dev = launcher.device
        self.margin = margin
        self.verts = wp.array(polygon.vertices, dtype=wp.vec2d, device=dev)
        self.acc = wp.zeros(3 * substeps, dtype=WP_DTYPE, device=dev)   # (F_x, F_y, M_z) impulse per stage
        g = GHOST
        self.yc_u = wp.array(grid.storage_y_centres(), dtype=WP_DTYPE, device=dev)
        self.yc_v = wp.array(grid.storage_y_faces(), dtype=WP_DTYPE, device=dev)
        self._yc_u_np = grid.storage_y_centres()
        self._yc_v_np = grid.storage_y_faces()
        self.hy_u = wp.array(grid.hy_cells(), dtype=WP_DTYPE, device=dev)
        self.hy_v = wp.array(grid.hy_faces(), dtype=WP_DTYPE, device=dev)
        self.x0 = float(grid.x_faces[0])
        self.dx = grid.dx
        self.xoff = {0: -float(g), 1: -float(g) + 0.5}
        self.limits = {0: (g + 1, g + grid.nx, g, g + grid.ny),
                       1: (g, g + grid.nx, g + 1, g + grid.ny)}
        self.boxes = {}
        self._pose = None
        self._closure_pose, self._closure_data = None, None
        self.area = polygon.area
        self.inertia = polygon.polar_moment_centroid
        self._centroid_body = polygon.centroid

    def set_wall_function(self, nu: float | None, nu_eff=None) -> None:
        """Interface faces take Spalding's law of the wall instead of the linear profile (a turbulent
        flow at high Reynolds number, ``kernels.cfd.ib_targets``; ``nu``: the molecular viscosity), or
        the linear profile again (None). Needs ``order`` 1. With ``nu_eff`` (the flow's nu + nu_t, a Warp
        array of cell storage) the law is blended with the linear profile by how far the reference face's
        eddy viscosity reaches the law's own: the linear profile where the layer is not turbulent."""
        if nu is not None:
            if self.order != 1:
                raise ValueError(f"the wall function needs interpolation order 1, not {self.order}")
            if not nu > 0:
                raise ValueError(f"wall function: nu must be > 0, got {nu}")
        self.wall_law = None if nu is None else float(nu)
        self._nu_eff = None if nu is None else nu_eff

    # --- geometry ------------------------------------------------------------------------------
    def _box(self, comp, pose):
        R = self.polygon.radius
        m = self.margin
        xr, yr = pose[0], pose[1]
        xoff = self.xoff[comp]
        i0 = int(math.floor((xr - R - self.x0) / self.dx - xoff)) - m
        i1 = int(math.ceil((xr + R - self.x0) / self.dx - xoff)) + m + 1
        yc = self._yc_u_np if comp == 0 else self._yc_v_np
        j0 = int(np.searchsorted(yc, yr - R)) - m
        j1 = int(np.searchsorted(yc, yr + R)) + m + 1
        ncol = self.grid.storage_shape("uv"[comp])[1]
        i0, i1 = max(i0, 1), min(i1, ncol - 1)
        j0, j1 = max(j0, 1), min(j1, yc.size - 1)
        if i1 - i0 < 3 or j1 - j0 < 3:
            raise ValueError(f"body at pose {pose} lies outside the grid")
        return i0, j0, i1 - i0, j1 - j0

    def update(self, t: float):
        """Classify faces for the body pose at time t (no work if the pose did not change)."""
        pose = tuple(float(q) for q in self.motion.pose(t))
        self.vel = wp.vec3d(*[float(q) for q in self.motion.velocity(t)])
        if pose == self._pose:
            return
        self._pose = pose
        self.pos = wp.vec3d(*pose)
        dev = self.L.device
        for comp in (0, 1):
            i0, j0, ni, nj = self._box(comp, pose)
            old = self.boxes.get(comp)
            if old is None or old["phi"].shape != (nj, ni):
                old = {"phi": wp.zeros((nj, ni), dtype=WP_DTYPE, device=dev),
                       "target": wp.zeros((nj, ni), dtype=WP_DTYPE, device=dev),
                       "state": wp.zeros((nj, ni), dtype=wp.int32, device=dev)}
            old.update(i0=i0, j0=j0, ni=ni, nj=nj)
            self.boxes[comp] = old
            yc = self.yc_u if comp == 0 else self.yc_v
            self.L.once(_k.ib_level_set, nj, [self.verts, self.x0, self.dx, self.xoff[comp], yc,
                                              self.pos, i0, j0, ni, old["phi"]])

    # --- forcing -------------------------------------------------------------------------------
    def _wall_code(self) -> int:
        """``kernels.cfd.ib_targets``'s wall_law: 0 linear, 1 Spalding's law, 2 the law blended."""
        return 0 if self.wall_law is None else (1 if self._nu_eff is None else 2)

    def apply(self, u, v, slot: int, p=None, c: float = 0.0):
        """Direct forcing on the predicted (u, v) in place; momentum added goes to ``acc[slot]``.

        ``p``, ``c``: pressure (cell storage) and projection factor for the compensation (module doc);
        ``p=None`` sets the bare targets.
        """
        for comp, q in ((0, u), (1, v)):
            b = self.boxes[comp]
            yc = self.yc_u if comp == 0 else self.yc_v
            ilo, ihi, jlo, jhi = self.limits[comp]
            self.L.once(_k.ib_targets, b["nj"], [q, b["phi"], self.x0, self.dx, self.xoff[comp], yc,
                                                 self.pos, self.vel, comp, b["i0"], b["j0"], b["ni"],
                                                 ilo, ihi, jlo, jhi, self.order, self._wall_code(),
                                                 0.0 if self.wall_law is None else float(self.wall_law),
                                                 self.verts, p if p is not None else q, self.hy_v,
                                                 float(c), int(p is not None),
                                                 q if self._nu_eff is None else self._nu_eff,
                                                 b["target"], b["state"]])
        self.close_targets()
        for comp, q in ((0, u), (1, v)):
            b = self.boxes[comp]
            yc = self.yc_u if comp == 0 else self.yc_v
            hy = self.hy_u if comp == 0 else self.hy_v
            self.L.once(_k.ib_apply, b["nj"], [q, b["target"], b["state"], self.x0, self.dx,
                                               self.xoff[comp], yc, hy, self.pos, comp, b["i0"], b["j0"],
                                               b["ni"], slot, p, self.hy_v, float(c),
                                               int(p is not None), self.acc])

    def _closure(self):
        """The constraint that makes the forced faces' targets divergence-free (module doc, Mass).

        Rows: cells whose four faces are all forced and at least one is an interface face; unknowns:
        those interface faces. Returns the constraint A (flux per unit velocity, rows x unknowns),
        a factorised A A^T, the four faces of every row (for the residual) and where the unknowns lie.
        """
        # face states on a window of storage covering both boxes (cells J0.., I0..)
        bu, bv = self.boxes[0], self.boxes[1]
        J0, I0 = min(bu["j0"], bv["j0"]), min(bu["i0"], bv["i0"])
        nj = max(bu["j0"] + bu["nj"], bv["j0"] + bv["nj"]) - J0
        ni = max(bu["i0"] + bu["ni"], bv["i0"] + bv["ni"]) - I0
        st = {0: self._face_states(0, J0, I0, (nj, ni + 1)), 1: self._face_states(1, J0, I0, (nj + 1, ni))}
        su, sv = st[0], st[1]
        # cell (J, I): u-faces (J, I) and (J, I + 1), v-faces (J, I) and (J + 1, I)
        all_forced = (su[:, :-1] != 0) & (su[:, 1:] != 0) & (sv[:-1, :] != 0) & (sv[1:, :] != 0)
        touches = (su[:, :-1] == 2) | (su[:, 1:] == 2) | (sv[:-1, :] == 2) | (sv[1:, :] == 2)
        j, i = np.nonzero(all_forced & touches)
        J, I = j + J0, i + I0
        n = J.size
        if n == 0:
            return None
        hy = self.grid.hy_cells()[J]
        wx = np.full(n, self.dx)
        faces = []  # (component, flat index in its box, outward flux per unit velocity, is interface)
        for c, FJ, FI, w in ((0, J, I + 1, hy), (0, J, I, -hy), (1, J + 1, I, wx), (1, J, I, -wx)):
            b = self.boxes[c]
            faces.append((c, (FJ - b["j0"]) * b["ni"] + (FI - b["i0"]), w, st[c][FJ - J0, FI - I0] == 2))
        big = max(self.boxes[c]["nj"] * self.boxes[c]["ni"] for c in (0, 1))
        rows = np.concatenate([np.nonzero(f[3])[0] for f in faces])
        keys = np.concatenate([f[0] * big + f[1][f[3]] for f in faces])
        vals = np.concatenate([f[2][f[3]] for f in faces])
        unknown, col = np.unique(keys, return_inverse=True)
        A = sp.csr_matrix((vals, (rows, col)), shape=(n, unknown.size))
        M = (A @ A.T).tocsc()
        # a ring of such cells with no interface face to the outside makes A A^T singular, with a
        # consistent right-hand side (zero rigid flux around it): a tiny shift picks the least-norm fix
        M = M + sp.identity(n, format="csc") * (1e-12 * M.diagonal().max())
        comp = unknown // big
        return {"A": A, "solve": factorized(M), "faces": [f[:3] for f in faces],
                "unknown": [(c, comp == c, unknown[comp == c] - c * big) for c in (0, 1)]}

    def close_targets(self):
        """Least change of the interface targets that leaves every all-forced cell divergence-free."""
        if self._closure_pose != self._pose:
            self._closure_data = self._closure()
            self._closure_pose = self._pose
        cl = self._closure_data
        if cl is None:
            return
        host = {c: self.boxes[c]["target"].numpy() for c in (0, 1)}
        flat = {c: host[c].reshape(-1) for c in (0, 1)}
        residual = sum(w * flat[c][idx] for c, idx, w in cl["faces"])
        delta = -(cl["A"].T @ cl["solve"](residual))
        for c, sel, idx in cl["unknown"]:
            flat[c][idx] += delta[sel]
            if not self.L.device.is_cpu:  # .numpy() copied the device array
                self.boxes[c]["target"].assign(host[c])

    def _face_states(self, comp, J0, I0, shape) -> np.ndarray:
        """States (0 fluid, 1 solid, 2 interface) of the ``comp`` faces of the latest ``apply`` on a
        window of storage starting at (J0, I0); faces outside the body's box are fluid."""
        out = np.zeros(shape, dtype=np.int32)
        b = self.boxes.get(comp)
        if b is not None:
            out[b["j0"] - J0:b["j0"] - J0 + b["nj"], b["i0"] - I0:b["i0"] - I0 + b["ni"]] = b["state"].numpy()
        return out

    def forced_cells(self) -> np.ndarray:
        """Cells (ny, nx) with at least one face forced (inside the body or at its interface) by the
        latest ``apply``. The pressure of such a cell is set by the forcing as much as by the flow (a
        DFG probe on a cell with three forced faces read a pressure difference of 81 instead of 0.12),
        so pressure probes use the other cells."""
        return self._cells(lambda state: state != 0, np.logical_or)

    def solid_cells(self) -> np.ndarray:
        """Cells (ny, nx) whose four faces are all inside the body (latest ``apply``)."""
        return self._cells(lambda state: state == 1, np.logical_and)

    def _cells(self, face_test, combine) -> np.ndarray:
        """Cells whose faces pass ``face_test`` (on the face states), combined over the four faces."""
        g, nx, ny = GHOST, self.grid.nx, self.grid.ny
        out = None
        for comp, (dj, di) in ((0, (0, 1)), (1, (1, 0))):
            mask = face_test(self._face_states(comp, 0, 0, self.grid.storage_shape("uv"[comp])))
            # the cell's two faces of this component: storage (J, I) and (J + dj, I + di)
            both = combine(mask[g:g + ny, g:g + nx], mask[g + dj:g + dj + ny, g + di:g + di + nx])
            out = both if out is None else combine(out, both)
        return out

    def reset_impulse(self):
        self.acc.zero_()

    # --- force ---------------------------------------------------------------------------------
    def _centroid_kinematics(self, t):
        x, y, th = self.motion.pose(t)
        u, v, om = self.motion.velocity(t)
        c, s = math.cos(th), math.sin(th)
        cx, cy = self._centroid_body
        rx, ry = c * cx - s * cy, s * cx + c * cy
        return np.array([x + rx, y + ry]), np.array([u - om * ry, v + om * rx]), om

    def force(self, weights, dt: float, t_old: float, t_new: float, rho: float) -> np.ndarray:
        """(F_x, F_y, M_z) on the body over the step t_old -> t_new (per unit length).

        weights[k]: how stage k's forcing enters the final velocity; M_z about the body reference
        point at t_new (counter-clockwise positive).
        """
        a = self.acc.numpy()
        m = sum(w * a[3 * k:3 * k + 3] for k, w in enumerate(weights))
        rc1, vc1, om1 = self._centroid_kinematics(t_new)
        _, vc0, om0 = self._centroid_kinematics(t_old)
        ac = (vc1 - vc0) / dt
        alpha = (om1 - om0) / dt
        x, y, _ = self.motion.pose(t_new)
        r = rc1 - np.array([x, y])
        fx = -m[0] / dt + self.area * ac[0]
        fy = -m[1] / dt + self.area * ac[1]
        mz = -m[2] / dt + self.inertia * alpha + self.area * (r[0] * ac[1] - r[1] * ac[0])
        return rho * np.array([fx, fy, mz])
