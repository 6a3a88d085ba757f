"""Reflection models, all in the local shading frame (normal = +Z)."""
