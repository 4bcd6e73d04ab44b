"""The deck section's own aerodynamics from the CFD: frequency response functions and flutter
derivatives from forced-motion runs (thesis 5.2-5.3).  See docs/aero.md."""

from bridge.aero.frequency_response import (
    DOFS,
    FRF_OF_RUN,
    LOADS,
    FrequencyResponse,
    FRFGrid,
    HarmonicFit,
    ThesisExtraction,
    displacement_frf,
    distortion,
    forced_motion_response,
    frf_table,
    harmonic_fit,
    normalised_frf,
    rate_frf,
    speed_independent_table,
    tabulate,
    thesis_extraction,
)

__all__ = ["DOFS", "FRF_OF_RUN", "LOADS", "FrequencyResponse", "FRFGrid", "HarmonicFit", "ThesisExtraction",
           "displacement_frf", "distortion", "forced_motion_response", "frf_table", "harmonic_fit", "normalised_frf",
           "rate_frf", "speed_independent_table", "tabulate", "thesis_extraction"]
