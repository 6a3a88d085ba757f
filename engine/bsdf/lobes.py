"""Lobe kinds, which Cycles' per-kind bounce limits count separately."""
DIFFUSE = 0
GLOSSY = 1
TRANSMISSION = 2
KIND_NAMES = ("diffuse", "glossy", "transmission")
