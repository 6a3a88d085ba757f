"""Integrators: each a short loop over the camera, sampler, lights and BSDF interfaces."""
