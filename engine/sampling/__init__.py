"""Samplers: where every random number of a render comes from."""
from .independent import IndependentSampler
from .sampler import Sampler
from .sobol import SobolSampler
from .stratified import StratifiedSampler

SAMPLERS = {cls.name: cls for cls in (StratifiedSampler, SobolSampler, IndependentSampler)}


def make_sampler(name: str, seed: int, samples_per_pixel: int) -> Sampler:
    try:
        cls = SAMPLERS[name]
    except KeyError:
        raise ValueError(f"unknown sampler {name!r}; choose one of {sorted(SAMPLERS)}") from None
    return cls(seed, samples_per_pixel)
