"""Advection schemes for the momentum equations (conservative flux form on the MAC grid).

Each face flux is u_f q_f with u_f the interpolated transport velocity and q_f reconstructed in
MUSCL form q_f = q_C + psi(r) w (q_D - q_C) from the upwind side:
  "central": psi = 1 (linear interpolation, second order, not bounded; for smooth/low-Re flows);
  "vanleer": van Leer's limiter psi = (r + |r|)/(1 + |r|) (TVD: second order in smooth regions,
             first-order upwind at extrema, stays bounded at high Reynolds number).
Source: van Leer (1974); Hirsch, Numerical Computation of Internal and External Flows, ch. 21.
"""

from kernels import cfd as _k

SCHEMES = {"central": _k.SCHEME_CENTRAL, "vanleer": _k.SCHEME_VANLEER}

__all__ = ["SCHEMES", "scheme_code"]


def scheme_code(name: str) -> int:
    """Integer code of an advection scheme name; unknown names raise ValueError."""
    if name not in SCHEMES:
        raise ValueError(f"advection scheme {name!r} unknown; allowed: {sorted(SCHEMES)}")
    return SCHEMES[name]
