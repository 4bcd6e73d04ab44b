"""Shared thin-plate sections for the flutter tests."""

import numpy as np
import pytest

from bridge.flutter.modal import ModalModel

RHO = 1.225


def plate_section(frequency_ratio: float, mass_ratio: float, radius_ratio: float, B: float = 30.0,
                  pitch_frequency_hz: float = 0.3, damping: float = 0.0) -> ModalModel:
    """A flat-plate section of chord B: m = mass_ratio * pi rho b^2, I = m (radius_ratio b)^2, b = B/2."""
    b = B / 2
    m = mass_ratio * np.pi * RHO * b**2
    return ModalModel.section(mass_per_length_kg_m=m, inertia_per_length_kg_m2_m=m * (radius_ratio * b) ** 2,
                              heave_frequency_hz=frequency_ratio * pitch_frequency_hz,
                              pitch_frequency_hz=pitch_frequency_hz, deck_width_m=B,
                              heave_damping_ratio=damping, pitch_damping_ratio=damping)


def selberg_speed(model: ModalModel, rho: float = RHO) -> float:
    """Selberg (1961): U_F = 0.44 B w_a sqrt((1 - (w_h/w_a)^2) sqrt(nu) / mu), nu = 8 r^2/B^2,
    mu = pi rho B^2 / (2 m), r^2 = I/m (docs/reference_cases.md)."""
    B, m, I = model.deck_width_m, model.mass_per_length_kg_m, model.inertia_per_length_kg_m2_m
    wh, wa = model.angular_frequencies
    nu = 8 * (I / m) / B**2
    mu = np.pi * rho * B**2 / (2 * m)
    return 0.44 * B * wa * np.sqrt((1 - (wh / wa) ** 2) * np.sqrt(nu) / mu)


@pytest.fixture
def section():
    return plate_section(0.4, 50.0, 0.7)
