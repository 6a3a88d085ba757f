"""DRT's render settings, stored in the .blend as `scene.drt`."""
import hashlib

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty

SAMPLER_ITEMS = [
    ("jittered", "Jittered", "Stratified jittered samples with Cook's ray-id chaining across "
     "dimensions (correlated multi-jittering)"),
    ("sobol", "Sobol", "Owen-scrambled Sobol quasi-Monte Carlo points"),
    ("random", "Random", "Independent uniform random samples (a baseline)"),
]
INTEGRATOR_ITEMS = [
    ("path", "Path Tracing", "Kajiya path tracing: full global illumination with next-event "
     "estimation and multiple importance sampling"),
    ("distribution", "Distribution", "Cook 1984: soft shadows, blurry reflection and "
     "translucency, depth of field and motion blur, but no diffuse interreflection"),
    ("whitted", "Whitted", "Whitted 1980: hard shadows and mirror reflection/refraction "
     "only (the baseline)"),
]

# The engine settings DRT reads from the file's Cycles settings (`scene.cycles`, shown in
# DRT's Light Paths and Film panels): engine name -> (Cycles property, Cycles' default).
CYCLES_SHARED = {
    "max_bounces": ("max_bounces", 12), "diffuse_bounces": ("diffuse_bounces", 4),
    "glossy_bounces": ("glossy_bounces", 4),
    "transmission_bounces": ("transmission_bounces", 12),
    "transparent_bounces": ("transparent_max_bounces", 8),
    "volume_bounces": ("volume_bounces", 0),
    "clamp_direct": ("sample_clamp_direct", 0.0),
    "clamp_indirect": ("sample_clamp_indirect", 10.0),
    "filter_glossy": ("blur_glossy", 1.0),
    "caustics_reflective": ("caustics_reflective", True),
    "caustics_refractive": ("caustics_refractive", True),
    "light_tree": ("use_light_tree", True),
    "film_exposure": ("film_exposure", 1.0),
    "filter_type": ("pixel_filter_type", "BLACKMAN_HARRIS"),
    "filter_width": ("filter_width", 1.5),
}


def file_seed(scene) -> int:
    """The file's Sampling > Advanced > Seed (`scene.cycles.seed`); with Use Animated Seed,
    a seed of its own for every frame and subframe, as Cycles hashes the seed with the
    frame (DRT's random numbers are not Cycles', so neither is the hash: what both give is
    independent noise from frame to frame, and the same image for the same frame)."""
    cycles = getattr(scene, "cycles", None)
    seed = int(getattr(cycles, "seed", 0))
    if not getattr(cycles, "use_animated_seed", False):
        return seed
    key = f"{seed}:{scene.frame_current}:{float(scene.frame_subframe)!r}".encode()
    return int.from_bytes(hashlib.blake2b(key, digest_size=4).digest(), "little") & 0x7FFFFFFF


class DRTRenderSettings(bpy.types.PropertyGroup):
    samples: IntProperty(name="Samples", description="Samples per pixel",
                         default=64, min=1, max=1 << 24, soft_max=4096)
    use_adaptive_sampling: BoolProperty(
        name="Noise Threshold", default=False,
        description="Adaptive sampling, as Cycles': pixels stop taking samples once their "
                    "error estimate is under the threshold (Samples is then the maximum)")
    adaptive_threshold: FloatProperty(
        name="Threshold", default=0.01, min=0.0, max=1.0, soft_min=0.001, soft_max=0.1,
        precision=4, description="Noise level at which a pixel stops; lower is less noise "
        "and more samples (0: automatic, max(0.001, 1 / Samples))")
    adaptive_min_samples: IntProperty(
        name="Min Samples", default=0, min=0, max=1 << 24, soft_max=4096,
        description="Samples every pixel takes before it may stop (0: automatic, from the "
                    "threshold: 64 at 0.01)")
    time_limit: FloatProperty(
        name="Time Limit", default=0.0, min=0.0, subtype="TIME_ABSOLUTE", unit="TIME_ABSOLUTE",
        description="Stop after this many seconds of tracing, or at Samples, whichever comes "
                    "first (0: no limit; export and acceleration structure do not count)")
    sampler: EnumProperty(name="Sampler", items=SAMPLER_ITEMS, default="jittered")
    integrator: EnumProperty(name="Integrator", items=INTEGRATOR_ITEMS, default="path")
    threads: IntProperty(name="Threads", description="Worker threads (0: Blender's own "
                         "fixed thread count (Performance > Threads, or `blender -t N`) "
                         "when set, else all cores)", default=0, min=0, max=256)

    def to_engine_settings(self):
        """The engine's settings: DRT's own, and the file's Cycles settings DRT shares
        with Cycles, in Cycles' own properties (Light Paths: the bounce limits per kind
        and the clamps, Filter Glossy, the caustics switches; Film > Exposure and Pixel
        Filter; the Seed, `file_seed`), Cycles' defaults where the Cycles add-on is off.
        export/file_settings.py lists every setting of the file and what DRT does with
        it."""
        from .engine_link import engine
        cycles = getattr(self.id_data, "cycles", None)
        shared = {key: type(default)(getattr(cycles, name, default))
                  for key, (name, default) in CYCLES_SHARED.items()}
        return engine.RenderSettings(
            **shared, samples=self.samples, seed=file_seed(self.id_data),
            adaptive_sampling=self.use_adaptive_sampling,
            adaptive_threshold=self.adaptive_threshold,
            adaptive_min_samples=self.adaptive_min_samples, time_limit=self.time_limit,
            sampler=self.sampler, integrator=self.integrator, threads=self.engine_threads())

    def engine_threads(self) -> int:
        """DRT's Threads; at 0, Blender's fixed thread count when there is one: Render
        Properties > Performance > Threads set to Fixed, or `blender -t N` on the command
        line, which Blender reports as Fixed with N threads (render farms: Deadline passes
        -t). Else 0, every core (up to 8)."""
        if self.threads:
            return self.threads
        render = getattr(self.id_data, "render", None)
        if render is not None and render.threads_mode == "FIXED":
            return render.threads
        return 0


def register():
    bpy.utils.register_class(DRTRenderSettings)
    bpy.types.Scene.drt = PointerProperty(type=DRTRenderSettings)


def unregister():
    del bpy.types.Scene.drt
    bpy.utils.unregister_class(DRTRenderSettings)
