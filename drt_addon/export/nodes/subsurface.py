"""Subsurface scattering as Cycles reads it (kernel/svm/closure.h): the Principled BSDF's
Subsurface inputs and the Subsurface Scattering node, to a `Subsurface` on the closure
(engine Material fields subsurface_*; the walk: engine/kernels/subsurface.py).

Principled BSDF: the diffuse base's share Subsurface Weight scatters below the surface
with the base colour as albedo, mean free path Subsurface Radius x Subsurface Scale,
Subsurface Anisotropy, and an entry refraction of the material's IOR (Random Walk) or
Subsurface IOR (Random Walk (Skin)) through GGX of alpha roughness^2.
Subsurface Scattering node: its Color is the albedo and the whole closure's weight;
Radius x Scale, Anisotropy, IOR, and Roughness as the entry's alpha (not squared, as
Cycles reads it).

Christensen-Burley has no entry refraction and no walk: the exit is found by Cycles' disk
sampling (engine/kernels/subsurface_disk.py); IOR, Anisotropy and Roughness do not apply.
Weight, radius, scale, IOR, anisotropy and roughness are constants: a linked one is its
average (reported by `_constant`)."""
from __future__ import annotations

from dataclasses import dataclass

from ...blender_compat import node_input

METHODS = ("RANDOM_WALK", "RANDOM_WALK_SKIN", "BURLEY")


@dataclass
class Subsurface:
    weight: float = 0.0                      # share of the diffuse base (1: the node)
    radius: tuple = (1.0, 0.2, 0.1)          # Radius x Scale, scene units
    anisotropy: float = 0.0
    ior: float = 1.4                         # the entry's IOR
    alpha: object = None                     # the entry's GGX alpha; None: roughness^2
    method: str = "RANDOM_WALK"


def _method(node, prop, ctx) -> str:
    method = getattr(node, prop, "RANDOM_WALK")
    if method not in METHODS:
        # Blender reads a method it does not know (a file from another version) as ''
        name = method.replace('_', ' ').title() if method else "a method Blender does not know"
        ctx.issue(f"{node.name!r} scatters below the surface by {name}; DRT renders it by "
                  f"Random Walk, as Cycles does")
        return "RANDOM_WALK"
    return method


def _radius(node, ctx, constant, name):
    sock = node_input(node, name)
    if sock is None:
        return (1.0, 0.2, 0.1)
    value = constant(node, name, ctx, tuple(sock.default_value)[:3], color=True)
    return tuple(float(x) for x in tuple(value)[:3])


def principled(node, ctx, constant, ior) -> Subsurface | None:
    """The Principled BSDF `node`'s subsurface scattering, or None when its weight is 0.
    constant: shader._constant; ior: the node's IOR."""
    sock = node_input(node, "Subsurface Weight")
    if sock is None:
        return None
    weight = min(max(float(constant(node, "Subsurface Weight", ctx, 0.0)), 0.0), 1.0)
    if weight <= 0.0:
        return None
    method = _method(node, "subsurface_method", ctx)
    scale = float(constant(node, "Subsurface Scale", ctx, 1.0)) \
        if node_input(node, "Subsurface Scale") is not None else 1.0
    radius = tuple(max(r * scale, 0.0) for r in _radius(node, ctx, constant,
                                                        "Subsurface Radius"))
    if method == "RANDOM_WALK_SKIN" and node_input(node, "Subsurface IOR") is not None:
        ior = float(constant(node, "Subsurface IOR", ctx, 1.4))
    aniso = float(constant(node, "Subsurface Anisotropy", ctx, 0.0)) \
        if node_input(node, "Subsurface Anisotropy") is not None else 0.0
    return Subsurface(weight, radius, aniso, float(ior), None, method)


def scattering_node(node, ctx, constant) -> Subsurface:
    """The Subsurface Scattering node's parameters (its Color is the closure's base)."""
    scale = float(constant(node, "Scale", ctx, 1.0))
    radius = tuple(max(r * scale, 0.0) for r in _radius(node, ctx, constant, "Radius"))
    roughness = float(constant(node, "Roughness", ctx, 1.0)) \
        if node.inputs.get("Roughness") is not None else 1.0
    aniso = float(constant(node, "Anisotropy", ctx, 0.0)) \
        if node.inputs.get("Anisotropy") is not None else 0.0
    ior = float(constant(node, "IOR", ctx, 1.4)) if node.inputs.get("IOR") is not None \
        else 1.4
    return Subsurface(1.0, radius, aniso, ior, min(max(roughness, 0.0), 1.0),
                      _method(node, "falloff", ctx))
