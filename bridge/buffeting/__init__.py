"""Buffeting: the deck's response to turbulent wind below the flutter speed, multimode, in the frequency
domain, with the flutter stage's modes and self-excited forces (wind.py: spectra and coherence;
admittance.py; loads.py: buffeting loads in modal coordinates; response.py; options.py: the [buffeting]
table; stage.py).  See docs/buffeting.md."""

from bridge.buffeting.options import BuffetingOptions

__all__ = ["BuffetingOptions"]
