"""Flutter analysis of long-span suspension bridges.

Pipeline (one module per concern):
  config / upscaling  - scenarios of the thesis and the up-scaling rules (thesis 1.4-1.5)
  cable               - cable statics (thesis ch. 2)
  structure           - 3D finite-element model and eigen analysis (thesis ch. 3)
  cfd                 - 2D URANS of the deck section (thesis ch. 5)
  flutter             - flutter condition and critical wind speed (thesis ch. 4, 5.4)
  pipeline / scenario - the stages and the command line ``python -m bridge.scenario``
"""

__version__ = "0.1.0"
