"""The law of the wall as Warp functions: Spalding's single formula for the inner layer of a turbulent
boundary layer (Spalding 1961, "A single formula for the law of the wall", J. Appl. Mech. 28: 455-458),

  y+ = u+ + exp(-kappa B) [exp(kappa u+) - 1 - kappa u+ - (kappa u+)^2 / 2 - (kappa u+)^3 / 6],

u+ = u / u_tau, y+ = y u_tau / nu, with the log-law constants kappa = 0.41, B = 5.0 (those of NASA's
Turbulence Modeling Resource, used by the project's log-law checks). It is u+ = y+ in the viscous
sublayer, the log law u+ = ln(y+) / kappa + B above y+ ~ 30, and a smooth blend between, so a wall
model built on it needs no switch between a resolved and a modelled wall: it is the resolved (linear)
profile when the first point lies in the sublayer. Used by the immersed boundary's wall function
(``kernels.cfd.ib_targets``) and the near-wall omega of the SST model (``kernels.transport``).

Both inversions are monotone root searches (the formula is increasing and convex in u+): safeguarded
Newton steps inside a shrinking bracket, a fixed number of iterations (Warp kernels have no early exit
that pays on the CPU), converged to round-off for y+ up to 1e7.
"""

import warp as wp

KAPPA = wp.constant(wp.float64(0.41))
B_LOG = wp.constant(wp.float64(5.0))
E_KB = wp.constant(wp.float64(0.12873490358780423))   # exp(-kappa B) = exp(-2.05)
_ITERATIONS = wp.constant(60)


@wp.func
def spalding_yplus(up: wp.float64):
    """y+ of Spalding's law at u+ (module doc)."""
    z = KAPPA * up
    return up + E_KB * (wp.exp(z) - wp.float64(1.0) - z - z * z / wp.float64(2.0) - z * z * z / wp.float64(6.0))


@wp.func
def spalding_slope(up: wp.float64):
    """d y+ / d u+ of Spalding's law at u+."""
    z = KAPPA * up
    return wp.float64(1.0) + E_KB * KAPPA * (wp.exp(z) - wp.float64(1.0) - z - z * z / wp.float64(2.0))


@wp.func
def spalding_uplus(yp: wp.float64):
    """u+ at y+ >= 0 (the inverse of ``spalding_yplus``); the root lies in [0, y+]."""
    lo = wp.float64(0.0)
    hi = wp.max(yp, wp.float64(0.0))
    x = wp.min(hi, wp.log(wp.float64(1.0) + KAPPA * hi) / KAPPA + B_LOG)
    for _ in range(_ITERATIONS):
        f = spalding_yplus(x) - yp
        if f > wp.float64(0.0):
            hi = x
        else:
            lo = x
        x_new = x - f / spalding_slope(x)
        if x_new <= lo or x_new >= hi:
            x_new = wp.float64(0.5) * (lo + hi)
        x = x_new
    return x


@wp.func
def friction_uplus(re_y: wp.float64):
    """u+ = U / u_tau of a point at distance y from the wall moving at U relative to it, from
    re_y = U y / nu >= 0: the root of u+ spalding_yplus(u+) = re_y (as y+ = re_y / u+), in [0, sqrt(re_y)]."""
    lo = wp.float64(0.0)
    hi = wp.sqrt(wp.max(re_y, wp.float64(0.0)))
    x = wp.min(hi, wp.log(wp.float64(1.0) + KAPPA * re_y) / KAPPA + B_LOG)
    for _ in range(_ITERATIONS):
        f = x * spalding_yplus(x) - re_y
        if f > wp.float64(0.0):
            hi = x
        else:
            lo = x
        x_new = x - f / (spalding_yplus(x) + x * spalding_slope(x))
        if x_new <= lo or x_new >= hi:
            x_new = wp.float64(0.5) * (lo + hi)
        x = x_new
    return x


@wp.func
def wall_law_ratio(speed: wp.float64, y_ref: wp.float64, y: wp.float64, nu: wp.float64):
    """u(y) / u(y_ref) on Spalding's profile through a point at distance y_ref moving at ``speed``
    relative to the wall (u_tau from that point); y / y_ref in the sublayer (the linear profile)."""
    ratio = y / y_ref
    if speed > wp.float64(0.0) and y_ref > wp.float64(0.0):
        up_ref = friction_uplus(speed * y_ref / nu)
        if up_ref > wp.float64(0.0):
            u_tau = speed / up_ref
            ratio = spalding_uplus(y * u_tau / nu) / up_ref
    return ratio


@wp.func
def wall_law_eddy_viscosity(speed: wp.float64, y: wp.float64, nu: wp.float64):
    """The eddy viscosity of Spalding's profile at a point at distance y moving at ``speed`` relative to the
    wall: nu (dy+/du+ - 1), which is kappa u_tau y in the log layer and vanishes in the sublayer."""
    nut = wp.float64(0.0)
    if speed > wp.float64(0.0) and y > wp.float64(0.0):
        nut = nu * (spalding_slope(friction_uplus(speed * y / nu)) - wp.float64(1.0))
    return nut
