"""The per-hit state slots of the lobes beyond Principled's base (layers.py and
hair_layer.py fill and read them), after principled.py's own (state.py)."""

WEIGHT_CUTOFF = 1e-5            # Cycles' CLOSURE_WEIGHT_CUTOFF
MIN_SELECTION = 0.02            # principled.MIN_SELECTION

S_FIRST = 33                    # principled.py's slots end here
S_BASE_SCALE = 33               # 3: the factor of every base lobe, per channel
S_COAT_W = 36                   # the coat lobe's weight (coat weight x sheen's factor)
S_COAT_ALPHA = 37               # the coat lobe's GGX alpha (Filter Glossy included)
S_COAT_IOR = 38
S_SHEEN_W = 39                  # 3: sheen weight x tint x R(wo)
S_SHEEN_A = 42                  # the LTC's a, b and frame (wo's azimuth cx, cy)
S_SHEEN_B = 43
S_SHEEN_CX = 44
S_SHEEN_CY = 45
S_TRANS = 46                    # 3: the translucent colour
S_EST_COAT = 49                 # selection estimates of the three lobes
S_EST_SHEEN = 50
S_EST_TRANS = 51
S_HAIR_T = 52                   # 3: the fibre's tangent, local
S_HAIR_R = 55                   # 3: the hair reflection's colour
S_HAIR_TT = 58                  # 3: the hair transmission's colour
S_HAIR_R_LOBE = 61              # 3: its offset (0 off a strand), r1, r2 (clamped)
S_HAIR_TT_LOBE = 64             # 3: the same for the transmission
S_EST_HAIR_R = 67               # selection estimates of the two hair lobes
S_EST_HAIR_TT = 68
S_CHIANG_W = 69                 # 3: the Principled Hair closure's weight colour
S_CHIANG_SIGMA = 72             # 3: its absorption
S_CHIANG_LOBE = 75              # 3: v, s, m0 (hair_chiang.remap, Filter Glossy included)
S_CHIANG_ALPHA = 78             # the node's Offset
S_CHIANG_ETA = 79
S_CHIANG_H = 80
S_CHIANG_T = 81                 # 3: the fibre's tangent, local
S_CHIANG_ALBEDO = 84            # 3: Cycles' albedo estimate at wo (the Color passes)
S_EST_CHIANG = 87               # its selection estimate
S_CHIANG_MESH = 88              # 1: on a triangle, where lights see Cycles' bump test
S_CHIANG_AS_SAMPLED = 89        # 1: principled.sample weighs the closure's own direction
S_SHEEN_N = 90                  # 3: the sheen's normal in the local frame ((0, 0, 1): the frame's)
S_COAT_N = 93                   # 3: the coat's normal in the local frame ((0, 0, 1): the frame's)
NSTATE = 96
