"""3D finite-element model of a suspension bridge and its eigen analysis (thesis chapter 3)."""
