"""What the BSDF kernels (engine/kernels/bsdf) read: the material table the exporter
fills (material_table.py) and the precomputed tables, with the code that integrates them
from the compiled lobes (energy_tables.py, layer_albedo.py) or fits them to Cycles
(sheen_table.py), stored in data/."""
