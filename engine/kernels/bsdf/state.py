"""The per-hit state vector of the compiled Principled BSDF (principled.setup fills it):
the slots of the base lobes here, those of the layers' lobes in layers.py, after them."""
from . import layers

S_DIFFUSE = 0        # 3: diffuse colour under the specular layer at wo, lobe weight included
S_EST = 3            # 5: selection estimates: diffuse, specular, metal, glass R, glass T
S_W_SPEC = 8         # lobe weights (the diffuse one is inside S_DIFFUSE)
S_W_METAL = 9
S_W_GLASS = 10
S_ALPHA = 11         # GGX alpha, clamped
S_EXPONENT = 12      # Blinn-Phong exponent matching alpha
S_BLINN = 13         # 1: the reflection lobes use Blinn-Phong instead of GGX
S_ETA_SPEC = 14      # IOR of the specular layer (adjusted by specular_ior_level)
S_METAL_F0 = 15      # 3: Schlick F0 of the metal lobe
S_ETA_GLASS = 18     # relative IOR of the glass lobe (1/ior on back faces)
S_GLASS_SMOOTH = 19  # 1: the glass lobe is the smooth (delta) interface
S_TINT = 20          # 3: refraction tint per crossing
S_MS_SPEC = 23       # multiple-scattering factor of the specular lobe (1: none)
S_MS_METAL = 24      # 3: ... of the metal lobe, per channel
S_MS_GLASS = 27      # 3: ... of the rough glass lobe, per channel
S_MS_E = 30          # GGX's E(wo) behind the factors (1: none)
S_REFRACT_ONLY = 31  # 1: the glass lobe refracts only (Refraction BSDF)
S_LAYERED = 32       # 1: the lobes of layers.py are in use (their slots follow)
S_WALTER = layers.NSTATE  # 1: refraction on Walter's pairs only, not Cycles' (dielectric.py)
S_BECKMANN = layers.NSTATE + 1  # 1: the microfacet lobes use Beckmann instead of GGX
S_METAL_CONST = layers.NSTATE + 2  # 1: the metal lobe's Fresnel is its F0 (Glossy BSDF)
S_METAL_F82 = layers.NSTATE + 3    # 1: the metal lobe's Fresnel is F82-tint (Specular Tint)
S_METAL_B = layers.NSTATE + 4      # 3: F82-tint's b per channel
S_SPEC_TINTED = layers.NSTATE + 7  # 1: the specular layer has a Specular Tint (specular_tint.py)
S_SPEC_F0 = layers.NSTATE + 8      # 3: ... its tinted F0 per channel
S_SPEC_MS = layers.NSTATE + 11     # 3: ... its multiscatter factor per channel
S_GLASS_TINTED = layers.NSTATE + 14  # 1: the glass lobe has a Specular Tint (specular_tint.py)
S_GLASS_F0 = layers.NSTATE + 15      # 3: ... its tinted F0 per channel
S_SSS = layers.NSTATE + 18          # 3: the subsurface lobe's weight (subsurface_lobe.py)
S_EST_SSS = layers.NSTATE + 21      # its selection estimate
S_E_SPEC = layers.NSTATE + 22       # the specular layer's albedo at wo (the Glossy Color pass)
S_ANY_SIDE = layers.NSTATE + 23     # 1: principled.sample's last direction may leave on
#                                     either side of the surface (a hair lobe's, as Cycles)
S_ON = layers.NSTATE + 24          # 5: Oren-Nayar a, b (b 0: Lambert) and its multiple-
#                                    scattering term per channel (oren_nayar.py)
S_GLASS_RTINT = layers.NSTATE + 29  # 3: the glass lobe's reflection tint (a Glass BSDF's Color)
S_DIFFUSE_LABEL = layers.NSTATE + 32  # 1: principled.sample's last direction is diffuse as
#                                       well as its kind: a Translucent BSDF's (Cycles'
#                                       LABEL_DIFFUSE | LABEL_TRANSMIT)
S_DIFFUSE_N = layers.NSTATE + 33   # 3: the diffuse lobe's normal in the local frame: (0, 0, 1),
#                                     or a bent frame's raw normal (bend_diffuse)
S_ANISO = layers.NSTATE + 36      # 1: the reflection lobes are anisotropic (anisotropic.py)
S_ALPHA_X = layers.NSTATE + 37     # ... their alpha along the tangent, Filter Glossy's included
S_ALPHA_Y = layers.NSTATE + 38     # ... across it
S_TAN_C = layers.NSTATE + 39       # cos and sin of the tangent's angle in the local frame
S_TAN_S = layers.NSTATE + 40
S_THIN_FILM = layers.NSTATE + 41  # the thin film's thickness (nm; 0: none, thin_film.py)
S_FILM_IOR = layers.NSTATE + 42    # ... its IOR
S_GLASS_IOR = layers.NSTATE + 43   # the glass lobe's IOR (a film on it: thin_film.py)
NSTATE = layers.NSTATE + 44
