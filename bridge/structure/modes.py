"""Mode classification, normalisation and the modal integrals of Eq 4.31-4.34.

Deck fields of a mode at the girder nodes (ascending z): U = u_y (vertical), Theta = theta_z (torsion
about the bridge axis), V = u_x (lateral), W = u_z (longitudinal).

Kind (thesis 4.4 uses "bending" and "torsional"): from the girder's modal kinetic energy shares,
with the deck's mu and J of Eq 4.7 as weights (trapezoidal integration along z):
    E_vertical = mu int U^2, E_torsional = J int Theta^2, E_lateral = mu int V^2, E_longitudinal = mu int W^2
the largest share names the mode; if the deck energy (the sum of the four terms, i.e. the girder with
the cable mass moving with it as Eq 4.7 assumes) is below ``CABLE_SHARE`` of the mode's total kinetic
energy phi^T M phi, the mode is a "cable" mode (cables, hangers or pylons move, the deck barely does).
The ratio can exceed 1 slightly where the cables swing less than the deck (lateral modes).  Symmetry about
mid-span: the dominant field f(z) is compared with its mirror
f(2 z_mid - z); correlation > 0 is "S", < 0 "SS".

Normalisation (Eq 4.31-4.32): vertical modes max|U| = 1, torsional max|Theta| = 1, lateral max|V| = 1,
longitudinal max|W| = 1, cable modes max |translation| = 1, each signed so that the maximum is +1.
Modal mass phi^T M phi of the normalised full 3D mode (kg; kg m^2 for torsional modes).

Modal integrals over the whole deck length L (main + side spans, Eq 4.34, generalised to pairs):
uu[i, j] = (1/L) int U_i U_j, ut[i, j] = (1/L) int U_i Theta_j, tt[i, j] = (1/L) int Theta_i Theta_j, by
the trapezoidal rule on the girder nodes (n_sub nodes per hanger panel; the refinement study shows the
effect).

Damping (thesis 1.5, 3.3: the Table 3.4 ratios are used for every bridge; :func:`assign_damping`): every
mode, whatever its kind, takes the ratio of the Table 3.4 row (``scenario.damping``) of the same symmetry
whose frequency is nearest to the mode's own (on a tie the earlier row); if the table has no row of that
symmetry, the nearest row of any symmetry; with an empty table, 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import Scenario

__all__ = ["ModeSet", "classify_modes", "KINDS_ALL", "CABLE_SHARE", "trapezoid_weights"]

KINDS_ALL = ("vertical", "torsional", "lateral", "longitudinal", "cable")
CABLE_SHARE = 0.25
_KIND_LETTER = {"vertical": "V", "torsional": "T", "lateral": "L", "longitudinal": "Z", "cable": "C"}


def trapezoid_weights(z: np.ndarray) -> np.ndarray:
    """w such that sum(w f) is the trapezoidal integral of f over the nodes z."""
    w = np.zeros(len(z))
    dz = np.diff(z)
    w[:-1] += 0.5 * dz
    w[1:] += 0.5 * dz
    return w


@dataclass(frozen=True)
class ModeSet:
    """Classified, normalised modes.  Arrays over modes (n,) unless noted; deck fields (n, n_z)."""

    frequencies_hz: np.ndarray
    kinds: tuple[str, ...]
    symmetries: tuple[str, ...]
    labels: tuple[str, ...]
    energy_shares: np.ndarray      # (n, 4): vertical, torsional, lateral, longitudinal of the deck energy
    deck_share: np.ndarray         # deck kinetic energy (Eq 4.7 mu, J) / total modal kinetic energy
    modal_masses: np.ndarray
    damping_ratios: np.ndarray
    z_m: np.ndarray
    U: np.ndarray
    Theta: np.ndarray
    V: np.ndarray
    W: np.ndarray
    shapes: np.ndarray             # (6 n_nodes, n) normalised full mode shapes
    deck_length_m: float
    mid_span_z_m: float

    def integral(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """(1/L) int a_i b_j dz over the deck (trapezoidal rule on the girder nodes), for deck fields
        a, b of shape (n, n_z): the modal integrals of Eq 4.34."""
        w = trapezoid_weights(self.z_m) / self.deck_length_m
        return (a * w) @ b.T

    @property
    def uu(self) -> np.ndarray:
        return self.integral(self.U, self.U)

    @property
    def ut(self) -> np.ndarray:
        return self.integral(self.U, self.Theta)

    @property
    def tt(self) -> np.ndarray:
        return self.integral(self.Theta, self.Theta)

    @property
    def vv(self) -> np.ndarray:
        """(1/L) int V_i V_j dz: lateral deck displacement (u_x) of mode i against mode j."""
        return self.integral(self.V, self.V)

    @property
    def uv(self) -> np.ndarray:
        """(1/L) int U_i V_j dz."""
        return self.integral(self.U, self.V)

    @property
    def vt(self) -> np.ndarray:
        """(1/L) int V_i Theta_j dz."""
        return self.integral(self.V, self.Theta)

    def index(self, label: str) -> int:
        return self.labels.index(label)

    def first(self, kind: str, symmetry: str, n: int = 1) -> list[int]:
        """Indices of the first ``n`` modes of this kind and symmetry (ascending frequency)."""
        return [i for i in range(len(self.labels)) if self.kinds[i] == kind and self.symmetries[i] == symmetry][:n]

    def pair_integrals(self) -> list[dict]:
        """a_jj, a_kk, a_jk (Eq 4.34) for the first three vertical modes of each symmetry with the first
        torsional mode of the same symmetry."""
        out = []
        uu, ut, tt = self.uu, self.ut, self.tt
        for sym in ("S", "SS"):
            k = self.first("torsional", sym)
            if not k:
                continue
            for j in self.first("vertical", sym, 3):
                out.append({"j": self.labels[j], "k": self.labels[k[0]], "symmetry": sym,
                            "a_jj": float(uu[j, j]), "a_kk": float(tt[k[0], k[0]]), "a_jk": float(ut[j, k[0]])})
        return out


def classify_modes(scenario: Scenario, frequencies_hz: np.ndarray, shapes_full: np.ndarray, mass_full,
                   girder_nodes: np.ndarray, z: np.ndarray, deck_length_m: float,
                   mid_span_z_m: float) -> ModeSet:
    """Classify, normalise and damp the modes (module docstring).  ``shapes_full`` (6 n_nodes, n) are the
    eigenvectors expanded to all DOFs, ``mass_full`` the full consistent mass matrix."""
    mu, J = scenario.deck_mass_per_length_kg_m, scenario.deck_inertia_per_length_kg_m2_m
    w = trapezoid_weights(z)
    n = shapes_full.shape[1]
    dof = 6 * girder_nodes
    shapes = shapes_full.copy()
    kinds, syms = [], []
    shares = np.zeros((n, 4))
    deck_share = np.zeros(n)
    mirror = 2.0 * mid_span_z_m - z
    for i in range(n):
        ph = shapes[:, i]
        fields = [ph[dof + 1], ph[dof + 5], ph[dof + 0], ph[dof + 2]]
        e = np.array([mu, J, mu, mu]) * np.array([w @ f**2 for f in fields])
        total = float(ph @ (mass_full @ ph))
        deck_share[i] = e.sum() / total if total > 0 else 0.0
        shares[i] = e / e.sum() if e.sum() > 0 else 0.0
        dominant = int(np.argmax(e))
        kind = ("vertical", "torsional", "lateral", "longitudinal")[dominant]
        if deck_share[i] < CABLE_SHARE:
            kind = "cable"
        f = fields[dominant]
        fm = np.interp(mirror, z, f)
        kinds.append(kind)
        syms.append("S" if w @ (f * fm) >= 0.0 else "SS")
        # normalisation Eq 4.31-4.32: the kind's field has max |.| = 1, signed so that the max is +1
        if kind == "cable":
            trans = ph.reshape(-1, 6)[:, :3].ravel()
            ref = trans[np.argmax(np.abs(trans))]
        else:
            ref = f[np.argmax(np.abs(f))]
        shapes[:, i] = ph / ref
    counters: dict[tuple[str, str], int] = {}
    labels = []
    for k, s in zip(kinds, syms, strict=False):
        counters[k, s] = counters.get((k, s), 0) + 1
        labels.append(f"{s}-{_KIND_LETTER[k]}{counters[k, s]}")
    modal_masses = np.einsum("di,di->i", shapes, mass_full @ shapes)
    damping = assign_damping(scenario.damping, frequencies_hz, syms)
    return ModeSet(
        frequencies_hz=np.asarray(frequencies_hz, dtype=np.float64), kinds=tuple(kinds), symmetries=tuple(syms),
        labels=tuple(labels), energy_shares=shares, deck_share=deck_share, modal_masses=modal_masses,
        damping_ratios=damping, z_m=z.copy(), U=shapes[dof + 1].T.copy(), Theta=shapes[dof + 5].T.copy(),
        V=shapes[dof + 0].T.copy(), W=shapes[dof + 2].T.copy(), shapes=shapes, deck_length_m=deck_length_m,
        mid_span_z_m=mid_span_z_m)


def assign_damping(table, frequencies_hz, symmetries) -> np.ndarray:
    """Damping ratio of each model mode from thesis Table 3.4 (``scenario.damping`` rows).

    Rule: a mode takes the ratio of the measured mode of the same symmetry (S / SS) whose frequency is
    nearest to its own.  Table 3.4 gives symmetry but not mode type, and the model has modes the
    measurement did not identify (lateral, cable), so matching by index or by rank would hand e.g. the
    first symmetric torsional mode (0.278 Hz here) the ratio of a measured mode at 0.429 Hz; by frequency it
    gets that of the 0.287 Hz mode it most likely is.  The up-scaled models use the same table (thesis 1.5),
    matched by their own frequencies.
    """
    out = np.zeros(len(frequencies_hz))
    for i, (f, s) in enumerate(zip(frequencies_hz, symmetries, strict=True)):
        rows = [d for d in table if d.symmetry == s] or list(table)
        if not rows:
            continue
        out[i] = min(rows, key=lambda d: abs(d.frequency_hz - f)).ratio
    return out
