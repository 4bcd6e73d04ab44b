"""Modal input of the flutter solvers: eigenfrequencies, damping and the modal integrals of Eq 4.34.

The flutter solvers do not care where the modes came from (the FEM stage, a sectional model, or data
typed in by a user); they consume a :class:`ModalModel`.

Normalisation (Eq 4.31-4.32) is the producer's job: a bending (vertical) mode is scaled so that
max |U| = 1 (its modal coordinate has the dimension of length), a torsional mode so that max |Theta| = 1
(its modal coordinate is non-dimensional).  The solvers only use the integrals ``uu``, ``ut``, ``tt``
and are correct for any normalisation as long as the three matrices and the modal masses agree.

Generalised modal integrals over the whole deck length L (main + side spans), Eq 4.34 extended to N modes:
    uu[i, j] = (1/L) int U_i U_j dz       (a_jj = uu[j, j])
    ut[i, j] = (1/L) int U_i Theta_j dz   (a_jk = ut[j, k])
    tt[i, j] = (1/L) int Theta_i Theta_j dz (a_kk = tt[k, k])
and, for lateral motion (R: lateral deck displacement, positive DOWNWIND; the thesis has no lateral
terms, so they default to zero):
    rr[i, j] = (1/L) int R_i R_j dz,  ur[i, j] = (1/L) int U_i R_j dz,  rt[i, j] = (1/L) int R_i Theta_j dz
Modal mass, Eq 4.8/4.33 generalised: m_i = L (mu (uu[i, i] + rr[i, i]) + J tt[i, i]), unless the
generalised masses are given directly (``generalised_masses``: a modal test or another FE program
reports them; they must belong to the same mode normalisation as the integrals).
Source: the thesis, sections 4.1 and 4.4.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bridge.errors import InputError, check_range

__all__ = ["ModalModel", "KINDS", "SYMMETRIES"]

KINDS = ("vertical", "torsional", "lateral")
SYMMETRIES = ("S", "SS")


def _matrix(name: str, value: object, n: int) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64)
    if a.shape != (n, n):
        raise InputError(f"modal.{name}", getattr(a, "shape", value), f"must have shape ({n}, {n})")
    if not np.all(np.isfinite(a)):
        raise InputError(f"modal.{name}", value, "must be finite")
    return a


@dataclass(frozen=True)
class ModalModel:
    """N undamped modes of the bridge with their modal integrals (see the module docstring).

    ``labels`` name the modes (e.g. ``"S-V1"``, ``"S-T1"``, ``"SS-V1"``); ``kinds`` are ``"vertical"``,
    ``"torsional"`` or ``"lateral"``; ``symmetries`` are ``"S"`` (symmetric) or ``"SS"`` (skew-symmetric).
    ``mass_per_length_kg_m`` is mu and ``inertia_per_length_kg_m2_m`` is J of Eq 4.7 (deck + cables);
    ``deck_width_m`` is B; ``deck_length_m`` is L (main + side spans).
    """

    labels: tuple[str, ...]
    kinds: tuple[str, ...]
    symmetries: tuple[str, ...]
    frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    uu: np.ndarray
    ut: np.ndarray
    tt: np.ndarray
    mass_per_length_kg_m: float
    inertia_per_length_kg_m2_m: float
    deck_width_m: float
    deck_length_m: float
    rr: np.ndarray | None = None
    ur: np.ndarray | None = None
    rt: np.ndarray | None = None
    generalised_masses: np.ndarray | None = None

    def __post_init__(self) -> None:
        labels = tuple(str(s) for s in self.labels)
        n = len(labels)
        if n == 0:
            raise InputError("modal.labels", self.labels, "needs at least one mode")
        if len(set(labels)) != n:
            raise InputError("modal.labels", self.labels, "labels must be unique")
        kinds, syms = tuple(self.kinds), tuple(self.symmetries)
        if len(kinds) != n:
            raise InputError("modal.kinds", kinds, f"needs one entry per mode ({n})")
        if len(syms) != n:
            raise InputError("modal.symmetries", syms, f"needs one entry per mode ({n})")
        for k in kinds:
            if k not in KINDS:
                raise InputError("modal.kinds", k, f"one of {', '.join(KINDS)}")
        for s in syms:
            if s not in SYMMETRIES:
                raise InputError("modal.symmetries", s, f"one of {', '.join(SYMMETRIES)}")
        f = np.asarray(self.frequencies_hz, dtype=np.float64).reshape(-1)
        z = np.asarray(self.damping_ratios, dtype=np.float64).reshape(-1)
        if f.shape != (n,):
            raise InputError("modal.frequencies_hz", self.frequencies_hz, f"needs one value per mode ({n})")
        if z.shape != (n,):
            raise InputError("modal.damping_ratios", self.damping_ratios, f"needs one value per mode ({n})")
        for i in range(n):
            check_range(f"modal.frequencies_hz[{i}]", float(f[i]), low=0.0, low_open=True)
            check_range(f"modal.damping_ratios[{i}]", float(z[i]), low=0.0, high=1.0, high_open=True)
        uu, ut, tt = _matrix("uu", self.uu, n), _matrix("ut", self.ut, n), _matrix("tt", self.tt, n)
        zero = np.zeros((n, n))
        rr, ur, rt = (zero.copy() if getattr(self, k) is None else _matrix(k, getattr(self, k), n)
                      for k in ("rr", "ur", "rt"))
        for name, a in (("uu", uu), ("tt", tt), ("rr", rr)):
            if not np.allclose(a, a.T, rtol=1e-9, atol=1e-12):
                raise InputError(f"modal.{name}", "non-symmetric matrix", "must be symmetric")
            if np.any(np.diag(a) < 0.0):
                raise InputError(f"modal.{name}", np.diag(a).tolist(), "diagonal must be >= 0")
        # every mode needs a deck motion (and so a modal mass); a lateral mode given without rr (the
        # thesis's model) has none and simply takes no part in the aerodynamics
        bad = [labels[i] for i in range(n) if kinds[i] != "lateral" and uu[i, i] + tt[i, i] <= 0.0]
        if bad:
            raise InputError("modal.uu/tt", bad, "every vertical/torsional mode needs uu[i,i] > 0 or tt[i,i] > 0")
        gm = None
        if self.generalised_masses is not None:
            gm = np.asarray(self.generalised_masses, dtype=np.float64).reshape(-1)
            if gm.shape != (n,):
                raise InputError("modal.generalised_masses", self.generalised_masses, f"needs one value per mode ({n})")
            for i in range(n):
                check_range(f"modal.generalised_masses[{i}]", float(gm[i]), low=0.0, low_open=True)
        mu = check_range("modal.mass_per_length_kg_m", self.mass_per_length_kg_m, low=0.0, low_open=True)
        J = check_range("modal.inertia_per_length_kg_m2_m", self.inertia_per_length_kg_m2_m,
                        low=0.0, low_open=True)
        B = check_range("modal.deck_width_m", self.deck_width_m, low=0.0, low_open=True)
        L = check_range("modal.deck_length_m", self.deck_length_m, low=0.0, low_open=True)
        for a in (f, z, uu, ut, tt, rr, ur, rt) + (() if gm is None else (gm,)):
            a.setflags(write=False)
        for name, value in (("labels", labels), ("kinds", kinds), ("symmetries", syms),
                            ("frequencies_hz", f), ("damping_ratios", z), ("uu", uu), ("ut", ut),
                            ("tt", tt), ("mass_per_length_kg_m", mu), ("inertia_per_length_kg_m2_m", J),
                            ("deck_width_m", B), ("deck_length_m", L), ("rr", rr), ("ur", ur), ("rt", rt),
                            ("generalised_masses", gm)):
            object.__setattr__(self, name, value)

    # ---------------------------------------------------------------- derived quantities
    @property
    def n_modes(self) -> int:
        return len(self.labels)

    @property
    def angular_frequencies(self) -> np.ndarray:
        """omega_i = 2 pi f_i [rad/s]."""
        return 2.0 * np.pi * self.frequencies_hz

    @property
    def has_lateral(self) -> bool:
        """True when some mode moves the deck laterally (rr, ur or rt not all zero)."""
        return bool(np.any(self.rr) or np.any(self.ur) or np.any(self.rt))

    @property
    def modal_masses(self) -> np.ndarray:
        """The given generalised masses, else Eq 4.8/4.33 generalised:
        m_i = L (mu (uu[i,i] + rr[i,i]) + J tt[i,i])  [kg, or kg m^2 for torsion]."""
        if self.generalised_masses is not None:
            return self.generalised_masses
        return self.deck_length_m * (self.mass_per_length_kg_m * (np.diag(self.uu) + np.diag(self.rr))
                                     + self.inertia_per_length_kg_m2_m * np.diag(self.tt))

    def index(self, label: str) -> int:
        if label not in self.labels:
            raise InputError("flutter.mode", label, f"one of {', '.join(self.labels)}")
        return self.labels.index(label)

    def modes_of(self, kind: str, symmetry: str) -> list[int]:
        """Indices of the modes of one kind and symmetry, in ascending frequency."""
        idx = [i for i in range(self.n_modes) if self.kinds[i] == kind and self.symmetries[i] == symmetry]
        return sorted(idx, key=lambda i: self.frequencies_hz[i])

    def pairs(self, which: str = "thesis", n_vertical: int = 3) -> list[tuple[int, int]]:
        """(bending, torsion) index pairs for the two-mode determinant method.

        ``"thesis"``: the first ``n_vertical`` symmetric vertical modes each with the first symmetric
        torsional mode (section 4.4, j = 1, 3, 5 and k = 1).  ``"all"``: those, then the same for the
        skew-symmetric modes.  Raises InputError if no pair can be formed.
        """
        if which == "thesis":
            symmetries = ("S",)
        elif which == "all":
            symmetries = ("S", "SS")
        else:
            raise InputError("flutter.pairs", which, "one of thesis, all")
        out: list[tuple[int, int]] = []
        for s in symmetries:
            torsion = self.modes_of("torsional", s)
            if torsion:
                out += [(j, torsion[0]) for j in self.modes_of("vertical", s)[:n_vertical]]
        if not out:
            raise InputError("flutter.modes", list(zip(self.labels, self.kinds, self.symmetries, strict=True)),
                             "needs at least one symmetric vertical and one symmetric torsional mode")
        return out

    def subset(self, indices: list[int] | tuple[int, ...]) -> ModalModel:
        """The model restricted to the given modes (in that order)."""
        ix = np.asarray(indices, dtype=int)
        return ModalModel(
            labels=tuple(self.labels[i] for i in ix), kinds=tuple(self.kinds[i] for i in ix),
            symmetries=tuple(self.symmetries[i] for i in ix), frequencies_hz=self.frequencies_hz[ix],
            damping_ratios=self.damping_ratios[ix], uu=self.uu[np.ix_(ix, ix)], ut=self.ut[np.ix_(ix, ix)],
            tt=self.tt[np.ix_(ix, ix)], mass_per_length_kg_m=self.mass_per_length_kg_m,
            inertia_per_length_kg_m2_m=self.inertia_per_length_kg_m2_m, deck_width_m=self.deck_width_m,
            deck_length_m=self.deck_length_m, rr=self.rr[np.ix_(ix, ix)], ur=self.ur[np.ix_(ix, ix)],
            rt=self.rt[np.ix_(ix, ix)],
            generalised_masses=None if self.generalised_masses is None else self.generalised_masses[ix])

    # ---------------------------------------------------------------- constructors
    @classmethod
    def from_two_modes(cls, *, bending_frequency_hz: float, torsion_frequency_hz: float,
                       a_jj: float, a_kk: float, a_jk: float, mass_per_length_kg_m: float,
                       inertia_per_length_kg_m2_m: float, deck_width_m: float, deck_length_m: float,
                       bending_damping_ratio: float = 0.0, torsion_damping_ratio: float = 0.0,
                       labels: tuple[str, str] = ("S-V1", "S-T1"), bending_modal_mass_kg: float | None = None,
                       torsion_modal_mass_kg_m2: float | None = None) -> ModalModel:
        """A bending mode j (Theta_j = 0) and a torsional mode k (U_k = 0), Eq 4.30, given a_jj, a_kk,
        a_jk of Eq 4.34 directly (e.g. the thesis's Table 3.6).  The modal masses are Eq 4.33's
        m_j = mu L a_jj, m_k = J L a_kk unless both are given (a modal test or another FE program:
        ``bending_modal_mass_kg`` for max |U_j| = 1, ``torsion_modal_mass_kg_m2`` for max |Theta_k| = 1)."""
        for key, v in (("a_jj", a_jj), ("a_kk", a_kk), ("bending_frequency_hz", bending_frequency_hz),
                       ("torsion_frequency_hz", torsion_frequency_hz), ("mass_per_length_kg_m", mass_per_length_kg_m),
                       ("inertia_per_length_kg_m2_m", inertia_per_length_kg_m2_m), ("deck_width_m", deck_width_m),
                       ("deck_length_m", deck_length_m)):  # named as the user typed them, before the arrays
            check_range(f"modal.{key}", v, low=0.0, low_open=True)
        for key, v in (("bending_damping_ratio", bending_damping_ratio),
                       ("torsion_damping_ratio", torsion_damping_ratio)):
            check_range(f"modal.{key}", v, low=0.0, high=1.0, high_open=True)
        check_range("modal.a_jk", a_jk)
        given = (bending_modal_mass_kg, torsion_modal_mass_kg_m2)
        if (given[0] is None) != (given[1] is None):
            raise InputError("modal.bending_modal_mass_kg" if given[0] is None else "modal.torsion_modal_mass_kg_m2",
                             None, "give both modal masses or neither (then Eq 4.33 from mu, J and a_jj, a_kk)")
        masses = None
        if given[0] is not None:
            masses = np.array([check_range("modal.bending_modal_mass_kg", given[0], low=0.0, low_open=True),
                               check_range("modal.torsion_modal_mass_kg_m2", given[1], low=0.0, low_open=True)])
        ut = np.zeros((2, 2))
        ut[0, 1] = a_jk
        return cls(labels=tuple(labels), kinds=("vertical", "torsional"), symmetries=("S", "S"),
                   frequencies_hz=np.array([bending_frequency_hz, torsion_frequency_hz], dtype=np.float64),
                   damping_ratios=np.array([bending_damping_ratio, torsion_damping_ratio], dtype=np.float64),
                   uu=np.diag([float(a_jj), 0.0]), ut=ut, tt=np.diag([0.0, float(a_kk)]),
                   mass_per_length_kg_m=mass_per_length_kg_m,
                   inertia_per_length_kg_m2_m=inertia_per_length_kg_m2_m,
                   deck_width_m=deck_width_m, deck_length_m=deck_length_m, generalised_masses=masses)

    @classmethod
    def section(cls, *, mass_per_length_kg_m: float, inertia_per_length_kg_m2_m: float,
                heave_frequency_hz: float, pitch_frequency_hz: float, deck_width_m: float,
                heave_damping_ratio: float = 0.0, pitch_damping_ratio: float = 0.0,
                lateral_frequency_hz: float | None = None, lateral_damping_ratio: float = 0.0) -> ModalModel:
        """A 2-DOF sectional model (rigid section on springs, elastic axis at mid-chord) of unit length,
        or 3-DOF with sway (lateral translation, same mass per length) when ``lateral_frequency_hz`` is set.

        Heave mode: U = 1, Theta = 0; pitch mode: U = 0, Theta = 1; sway mode: R = 1.  Hence uu = diag(1, 0),
        tt = diag(0, 1) and ut[heave, pitch] = (1/L) int U_heave Theta_pitch dz = 1 (a_jk = 1: the
        aerodynamic coupling is complete; with a_jk = 0 there would be no coupling and no flutter), and with
        sway rr[sway, sway] = ur[heave, sway] = rt[sway, pitch] = 1; the modal masses are the
        per-unit-length mass and inertia (L = 1 m)."""
        two = cls.from_two_modes(bending_frequency_hz=heave_frequency_hz,
                                 torsion_frequency_hz=pitch_frequency_hz, a_jj=1.0, a_kk=1.0, a_jk=1.0,
                                 mass_per_length_kg_m=mass_per_length_kg_m,
                                 inertia_per_length_kg_m2_m=inertia_per_length_kg_m2_m,
                                 deck_width_m=deck_width_m, deck_length_m=1.0,
                                 bending_damping_ratio=heave_damping_ratio,
                                 torsion_damping_ratio=pitch_damping_ratio, labels=("heave", "pitch"))
        if lateral_frequency_hz is None:
            return two
        check_range("section.lateral_frequency_hz", lateral_frequency_hz, low=0.0, low_open=True)
        check_range("section.lateral_damping_ratio", lateral_damping_ratio, low=0.0, high=1.0, high_open=True)

        def grow(a, corner=0.0):
            out = np.zeros((3, 3))
            out[:2, :2] = a
            out[2, 2] = corner
            return out

        ur, rt = np.zeros((3, 3)), np.zeros((3, 3))
        ur[0, 2] = 1.0   # heave U against sway R
        rt[2, 1] = 1.0   # sway R against pitch Theta
        return cls(labels=("heave", "pitch", "sway"), kinds=("vertical", "torsional", "lateral"),
                   symmetries=("S", "S", "S"),
                   frequencies_hz=np.array([heave_frequency_hz, pitch_frequency_hz, lateral_frequency_hz]),
                   damping_ratios=np.array([heave_damping_ratio, pitch_damping_ratio, lateral_damping_ratio]),
                   uu=grow(two.uu), ut=grow(two.ut), tt=grow(two.tt), rr=grow(np.zeros((2, 2)), 1.0), ur=ur, rt=rt,
                   mass_per_length_kg_m=mass_per_length_kg_m, inertia_per_length_kg_m2_m=inertia_per_length_kg_m2_m,
                   deck_width_m=deck_width_m, deck_length_m=1.0)

    # ---------------------------------------------------------------- scenario input
    @classmethod
    def from_mapping(cls, mapping, where: str = "modal") -> ModalModel:
        """A ``[modal]`` table of a scenario file.  Either the full form (keys = the field names;
        uu, ut, tt as lists of rows; optional rr, ur, rt for lateral motion and generalised_masses, one
        per mode, to give the modal masses directly) or the two-mode form of :meth:`from_two_modes` (keys
        bending_frequency_hz, torsion_frequency_hz, a_jj, a_kk, a_jk, mass_per_length_kg_m,
        inertia_per_length_kg_m2_m, deck_width_m, deck_length_m, optional bending_damping_ratio,
        torsion_damping_ratio, labels, bending_modal_mass_kg and torsion_modal_mass_kg_m2).  Unknown or
        missing keys raise InputError naming ``where.key``."""
        import dataclasses
        import inspect
        from collections.abc import Mapping
        from dataclasses import fields

        if not isinstance(mapping, Mapping):
            raise InputError(where, mapping, "must be a table")
        two_mode = "a_jj" in mapping
        if two_mode:
            params = inspect.signature(cls.from_two_modes).parameters
            allowed = list(params)
            required = [k for k, p in params.items() if p.default is inspect.Parameter.empty]
        else:
            allowed = [f.name for f in fields(cls)]
            required = [f.name for f in fields(cls) if f.default is dataclasses.MISSING]
        for key in mapping:
            if key not in allowed:
                raise InputError(f"{where}.{key}", mapping[key], f"unknown key; allowed: {', '.join(allowed)}")
        for key in required:
            if key not in mapping:
                raise InputError(f"{where}.{key}", None, "missing (required key)")
        values = dict(mapping)
        for key in ("labels", "kinds", "symmetries"):
            if key in values:
                if not isinstance(values[key], (list, tuple)) or not all(isinstance(s, str) for s in values[key]):
                    raise InputError(f"{where}.{key}", values[key], "a list of strings")
                values[key] = tuple(values[key])
        try:
            return cls.from_two_modes(**values) if two_mode else cls(**values)
        except InputError as err:  # re-key to the caller's dotted path
            key = err.key.replace("modal.", f"{where}.", 1) if err.key.startswith("modal.") else err.key
            raise InputError(key, err.value, err.allowed) from None
        except (TypeError, ValueError) as err:
            raise InputError(where, str(err), "numbers and lists of numbers as documented") from None
