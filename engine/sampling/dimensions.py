"""Where each random decision of a path reads its numbers: the sample-space layout.

Cook's distribution ray tracing gives every primary sample an id, and that id selects the
sample's stratum in every other dimension (lens, time, light, reflection, transmission)
through a per-dimension permutation. Here a dimension is an integer; the samplers turn
(seed, pixel, sample index, dimension) into a point in [0,1)^2 (or [0,1)), stratified
across the sample indices of one pixel within each dimension and decorrelated between
dimensions.

The layout is fixed so that adding an effect never shifts the numbers another effect sees;
an effect a scene does not use is simply never asked for (no lens, no time dimension).
"""
PIXEL = 0          # 2D: sub-pixel position (through the pixel filter)
LENS = 1           # 2D: point on the aperture
TIME = 2           # 1D: time within the shutter
FIRST_BOUNCE = 3   # per-bounce dimensions start here

# Offsets within one bounce's block.
LIGHT_PICK = 0     # 1D: which light
LIGHT_POINT = 1    # 2D: where on that light
BSDF_LOBE = 2      # 1D: which lobe (diffuse, specular, transmission...)
BSDF_DIR = 3       # 2D: direction within the lobe
ROULETTE = 4       # 1D: Russian roulette
PER_BOUNCE = 5


def bounce_dim(bounce: int, offset: int) -> int:
    """The dimension index of `offset` at path vertex `bounce` (0 = first hit)."""
    return FIRST_BOUNCE + bounce * PER_BOUNCE + offset
