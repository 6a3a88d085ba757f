"""The BSDFs, as compiled scalar kernels: material rows (`pack_materials`), a per-hit
state (`setup`), and `eval_f`, `pdf`, `sample`, `transmits` on it; one module per lobe
(microfacet, dielectric, fresnel, blinn_phong, beckmann, sheen, ...). Array drivers for
tests and tables: `batch` (the whole BSDF), `lobe_batch` (single lobes), `table_batch`
(the table lookups). See `principled` for the model and the calling protocol."""
from .params import (GLOSSY_BLINN_PHONG, GLOSSY_GGX, GLOSSY_MULTI_GGX, NPARAM, P_BASE,
                     P_FILTER_ALPHA, P_GLASS_COLOR, P_GLOSSY_MODEL, P_HAS_GLASS_COLOR,
                     P_HAS_METAL_COLOR, P_IOR, P_METAL_COLOR, P_METALLIC, P_ROUGHNESS,
                     P_SPEC_LEVEL, P_TRANSMISSION, pack_materials)
from .tables import kernel_tables
from .principled import (DIFFUSE, GLOSSY, NSTATE, TRANSMISSION, eval_f, pdf, sample,
                         setup, transmits)

__all__ = [
    "NPARAM", "NSTATE", "P_BASE", "P_METALLIC", "P_ROUGHNESS", "P_IOR", "P_TRANSMISSION",
    "P_SPEC_LEVEL", "P_METAL_COLOR", "P_HAS_METAL_COLOR", "P_GLASS_COLOR",
    "P_HAS_GLASS_COLOR", "P_GLOSSY_MODEL", "GLOSSY_GGX", "GLOSSY_BLINN_PHONG",
    "GLOSSY_MULTI_GGX", "P_FILTER_ALPHA",
    "DIFFUSE", "GLOSSY", "TRANSMISSION",
    "pack_materials", "kernel_tables", "setup", "eval_f", "pdf", "sample", "transmits",
]
