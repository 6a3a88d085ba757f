"""The file's render settings (Cycles', Blender's render and view-layer settings): which
DRT reads, which it replaces by its own, which Blender applies for it, and which it
ignores, with one warning per ignored setting the file changed.

SETTINGS is the one table: export.settings_check warns from it when a scene is exported,
and docs/make_settings_docs.py writes docs/settings.md from it. Each row is a setting by
its path from the scene (`scene.cycles.film_exposure`) or from the view layer being
rendered (`view_layer.samples`), its place in Blender's interface, what DRT does with it
(`kind`, `how`) and, for the settings DRT does not honour, the value at which ignoring it
changes nothing (`quiet`). That value is Blender's default except for Adaptive
Sampling, which Blender turns on by default and DRT's own switch leaves off.
"""
from __future__ import annotations

from .file_setting_rows import (_ADAPTIVE, _NO_VOLUMES, _NULL_SCATTERING, _PASSES_HOW,
                                _SIMPLIFY, BLENDER, IGNORED, KINDS, NO_EFFECT, NOISE_ONLY, OWN,
                                READ, WRITTEN_PASSES, FileSetting, _ignored, _no_effect, _own,
                                _part_of, _s)

__all__ = ["BLENDER", "FileSetting", "IGNORED", "KINDS", "NO_EFFECT", "NOISE_ONLY", "OWN", "READ",
           "SETTINGS", "WRITTEN_PASSES"]

# Render passes DRT does not write, as (path, label).
_PART_HOW = {"direct": "next-event estimation at the first surface and what its bounce finds",
             "indirect": "every later bounce"}
_UNWRITTEN_PASSES = [
    ("view_layer.use_pass_subsurface_direct", "Subsurface Direct"),
    ("view_layer.use_pass_subsurface_indirect", "Subsurface Indirect"),
    ("view_layer.use_pass_subsurface_color", "Subsurface Color"),
    ("view_layer.cycles.use_pass_volume_scatter", "Volume Scatter"),
    ("view_layer.cycles.use_pass_volume_transmit", "Volume Transmit"),
    ("view_layer.cycles.use_pass_volume_majorant", "Volume Majorant"),
    ("view_layer.use_pass_shadow", "Shadow"),
    ("view_layer.cycles.denoising_store_passes", "Denoising Data (Cycles')"),
    ("view_layer.cycles.pass_debug_sample_count", "Sample Count"),
    ("view_layer.cycles.pass_render_time", "Render Time"),
]

SETTINGS: list[FileSetting] = [
    # -- read from the file, as Cycles reads them
    _s("scene.render.resolution_x", "Output > Resolution X", READ, "the image's width"),
    _s("scene.render.resolution_y", "Output > Resolution Y", READ, "the image's height"),
    _s("scene.render.resolution_percentage", "Output > Resolution %", READ,
       "scales the resolution with Blender's integer arithmetic"),
    _s("scene.render.pixel_aspect_x", "Output > Aspect X", READ,
       "pixel aspect, as Cycles' camera"),
    _s("scene.render.pixel_aspect_y", "Output > Aspect Y", READ,
       "pixel aspect, as Cycles' camera"),
    _s("scene.render.use_border", "Output > Render Region", READ,
       "only the region's pixels are traced"),
    *[_s(f"scene.render.border_{e}", f"Output > Render Region > {e}", READ,
         "the region's edge, with Blender's float32 arithmetic")
      for e in ("min_x", "min_y", "max_x", "max_y")],
    _s("scene.render.engine", "Render Engine", READ, "DRT renders when it is DRT"),
    _s("scene.render.film_transparent", "Film > Transparent", READ,
       "the background has alpha 0, holdouts cut holes, as in Cycles"),
    _s("scene.cycles.film_exposure", "Film > Exposure", READ,
       "every radiance sample is multiplied by it as it enters the film: the Combined "
       "pass and DRT Noise scale by it, Depth, Normal and Denoising Data do not, as in "
       "Cycles; clamping acts before it"),
    _s("scene.cycles.blur_glossy", "Light Paths > Caustics > Filter Glossy", READ,
       "widens glossy lobes after a diffuse or rough bounce, as Cycles"),
    _s("scene.cycles.caustics_reflective", "Light Paths > Caustics > Reflective", READ,
       "off: no glossy reflection at hits after a diffuse bounce, as Cycles"),
    _s("scene.cycles.caustics_refractive", "Light Paths > Caustics > Refractive", READ,
       "off: no refraction at hits after a diffuse bounce, as Cycles"),
    _s("scene.render.use_motion_blur", "Motion Blur", READ,
       "the scene is sampled over the shutter (docs/motion_blur.md)"),
    _s("scene.render.motion_blur_shutter", "Motion Blur > Shutter", READ,
       "the shutter's length in frames"),
    _s("scene.render.motion_blur_position", "Motion Blur > Position", READ,
       "start, centre or end on the frame"),
    _s("scene.render.motion_blur_shutter_curve", "Motion Blur > Shutter Curve", READ,
       "the shutter's openness over time, sampled as Cycles samples it"),
    _s("scene.world.cycles.sampling_method", "World > Settings > Surface > Sampling Method",
       READ, "None: the world is not sampled as a light (only escaping rays find it); "
       "Auto and Manual: it is where it varies over directions (a texture or coordinates "
       "feed it), by its own importance map; a world of one colour never is, as in "
       "Cycles"),
    _s("scene.world.cycles.sample_map_resolution", "World > Settings > Surface > Map "
       "Resolution", NO_EFFECT, "DRT's importance map has the image's own resolution: "
       + NOISE_ONLY),
    _s("view_layer.use_pass_combined", "Passes > Combined", READ, "written"),
    _s("view_layer.use_pass_z", "Passes > Z", READ, "written: camera-space depth"),
    _s("view_layer.use_pass_normal", "Passes > Normal", READ, "written: world-space normal"),
    _s("view_layer.use_pass_mist", "Passes > Mist", READ,
       "written: Cycles' mist of the first hit (World > Mist Pass)"),
    _s("view_layer.use_pass_position", "Passes > Position", READ,
       "written: world-space position of the first hit"),
    _s("view_layer.use_pass_uv", "Passes > UV", READ,
       "written: UV of the first hit (the active UV map unless a material names one) and "
       "its coverage"),
    _s("view_layer.use_pass_object_index", "Passes > Object Index", READ,
       "written: the Pass Index of the object the pixel's first sample hits (Cycles' "
       "IndexOB)"),
    _s("view_layer.use_pass_environment", "Passes > Environment", READ,
       "written: the world as camera rays see it, through transparent surfaces and on a "
       "transparent film too, every sample (Cycles' Environment)"),
    *[_s(f"view_layer.use_pass_{kind}_{part}", f"Passes > {kind.title()} {part.title()}",
         READ, f"written: the light of paths that first scattered off a {kind} lobe "
         f"({_PART_HOW[part]}), divided by {kind.title()} Color as Cycles writes it")
      for kind in ("diffuse", "glossy", "transmission") for part in ("direct", "indirect")],
    *[_s(f"view_layer.use_pass_{kind}_color", f"Passes > {kind.title()} Color", READ,
         f"written: what the first surface's {kind} lobes weigh at the view (their albedo "
         "estimates), as Cycles' closure weights")
      for kind in ("diffuse", "glossy", "transmission")],
    *[_s(f"view_layer.cycles.use_pass_volume_{part}", f"Passes > Volume {part.title()}",
         READ, "written: the light of paths that first scattered in a medium")
      for part in ("direct", "indirect")],
    _s("view_layer.cycles.use_pass_shadow_catcher", "Passes > Shadow Catcher", READ,
       "written: what other objects do to shadow catcher objects (1: nothing), and "
       "Combined becomes the matte alone, as Cycles' (off: the shadow is laid into "
       "Combined, Cycles' approximation)"),
    _s("view_layer.use_pass_emit", "Passes > Emission", READ,
       "written: what camera rays see emitted (lamps, emissive surfaces and media)"),
    _s("view_layer.use_pass_vector", "Passes > Vector", READ,
       "written: motion vectors from the frames before and after, as Cycles' (zeros with "
       "motion blur on, as Cycles writes them)"),
    _s("view_layer.use_pass_ambient_occlusion", "Passes > Ambient Occlusion", READ,
       "written: the share of cosine-weighted directions from the first hit that reach "
       "World > Ambient Occlusion > Distance unoccluded (Cycles' AO), min(samples, 64) "
       "rays per pixel"),
    _s("scene.world.light_settings.distance", "World > Ambient Occlusion > Distance", READ,
       "read by the Ambient Occlusion pass (10 m without a world, as Cycles)"),
    _s("view_layer.use_pass_material_index", "Passes > Material Index", READ,
       "written: the Pass Index of the material the pixel's first sample hits (Cycles' "
       "IndexMA)"),
    *[_s(f"scene.world.mist_settings.{name}", f"World > Mist Pass > {label}", READ,
         "read by the Mist pass") for name, label in
      (("start", "Start"), ("depth", "Depth"), ("falloff", "Falloff"))],
    # -- DRT's own settings (Render Properties with DRT selected) replace these
    _own("samples", "Sampling > Render > Max Samples", "samples",
         "Samples (DRT's Sampling panel)", 4096),
    _s("scene.cycles.seed", "Sampling > Advanced > Seed", READ, "DRT renders with the "
       "file's Seed, shown in DRT's Sampling panel (DRT's random numbers are its own: the "
       "same seed gives the same image in DRT, not Cycles' noise)"),
    *[_s(f"scene.cycles.{name}", label, READ, "DRT renders with the file's value, shown "
         "in DRT's Light Paths panel, as Cycles does") for name, label in (
        ("max_bounces", "Light Paths > Max Bounces > Total"),
        ("diffuse_bounces", "Light Paths > Max Bounces > Diffuse"),
        ("glossy_bounces", "Light Paths > Max Bounces > Glossy"),
        ("transmission_bounces", "Light Paths > Max Bounces > Transmission"),
        ("transparent_max_bounces", "Light Paths > Max Bounces > Transparent"),
        ("volume_bounces", "Light Paths > Max Bounces > Volume"),
        ("sample_clamp_direct", "Light Paths > Clamping > Direct Light"),
        ("sample_clamp_indirect", "Light Paths > Clamping > Indirect Light"))],
    *[_s(f"scene.cycles.{name}", label, READ, "DRT renders with the file's value, shown "
         "in DRT's Film panel, as Cycles does (Blackman-Harris, Gaussian or Box)")
      for name, label in (("pixel_filter_type", "Film > Pixel Filter > Type"),
                          ("filter_width", "Film > Pixel Filter > Width"))],
    # -- applied by Blender, to DRT's result as to Cycles'
    _s("scene.view_settings", "Color Management (view transform, look, exposure, gamma, "
       "curves)", BLENDER, "Blender maps DRT's scene-linear result for display and for "
       "8/16-bit files, as it does Cycles'"),
    _s("scene.display_settings.display_device", "Color Management > Display", BLENDER,
       "applied by Blender"),
    _s("scene.render.dither_intensity", "Post Processing > Dither", BLENDER,
       "applied by Blender"),
    _s("scene.render.use_compositing", "Post Processing > Compositing", BLENDER,
       "Blender composites DRT's passes"),
    _s("scene.render.use_sequencer", "Post Processing > Sequencer", BLENDER,
       "applied by Blender"),
    _s("scene.render.use_crop_to_border", "Output > Crop to Render Region", BLENDER,
       "Blender crops or places the region DRT renders"),
    _s("scene.render.simplify_subdivision_render", "Simplify > Render > Max Subdivision",
       BLENDER, "Blender's modifiers apply it to the meshes DRT exports"),
    _s("scene.render.simplify_child_particles_render", "Simplify > Render > Max Child "
       "Particles", BLENDER, "Blender applies it to the evaluated objects"),
    _s("view_layer.use", "View Layer > Use for Rendering", BLENDER,
       "Blender asks DRT for each enabled view layer"),
    _s("view_layer.use_grease_pencil", "View Layer > Filter > Grease Pencil", BLENDER,
       "Blender's render pipeline draws Grease Pencil over DRT's result, as over Cycles'"),
    _s("view_layer.use_pass_grease_pencil", "Passes > Grease Pencil", BLENDER,
       "written by Blender's Grease Pencil renderer"),
    _s("scene.render.use_single_layer", "View Layer > Render Single Layer", BLENDER,
       "Blender asks DRT for the active view layer only"),
    _s("scene.render.use_simplify", "Simplify", BLENDER, "Blender applies its render "
       "limits (subdivision, child particles); Cycles' own Simplify settings are warned"),
    # -- ignored: a warning when the file changes them
    _s("scene.cycles.use_denoising", "Sampling > Render > Denoise", READ,
       "DRT denoises its final render with OpenImageDenoise, as Cycles does, and keeps "
       "the noisy one as the Noisy Image pass (DRT's Sampling > Denoise panel shows it)"),
    *[_s(f"scene.cycles.{name}", f"Sampling > Render > Denoise > {label}", READ,
         "read, as Cycles reads it") for name, label in [
        ("denoising_input_passes", "Passes"), ("denoising_prefilter", "Prefilter"),
        ("denoising_quality", "Quality")]],
    _s("scene.cycles.denoiser", "Sampling > Render > Denoise > Denoiser", READ,
       "OpenImageDenoise; OptiX (NVIDIA GPUs only) is denoised with OpenImageDenoise, "
       "with a warning, as Cycles does without such a GPU"),
    _s("scene.cycles.denoising_use_gpu", "Sampling > Render > Denoise > Use GPU", NO_EFFECT,
       "DRT denoises on the CPU"),
    _own("use_adaptive_sampling", "Sampling > Render > Noise Threshold (adaptive "
         "sampling)", "use_adaptive_sampling", "Noise Threshold switch (DRT's Sampling "
         "panel)", True),
    _own("adaptive_threshold", "Sampling > Render > Noise Threshold", "adaptive_threshold",
         "Noise Threshold (DRT's Sampling panel)", 0.01, when=_ADAPTIVE),
    _own("adaptive_min_samples", "Sampling > Render > Min Samples", "adaptive_min_samples",
         "Min Samples (DRT's Sampling panel)", 0, when=_ADAPTIVE),
    _own("time_limit", "Sampling > Render > Time Limit", "time_limit",
         "Time Limit (DRT's Sampling panel)", 0.0),
    _ignored("scene.cycles.use_sample_subset", "Sampling > Advanced > Sample Subset",
             "DRT renders all its samples (the engine can render a sample range, "
             "engine.render(sample_start, sample_end), but the add-on does not)", False),
    *_part_of("Sampling > Advanced > Sample Subset", ["sample_offset",
              "sample_subset_length"]),
    _ignored("scene.cycles.use_layer_samples", "Sampling > Advanced > Layer Samples",
             "DRT renders every view layer with its own Samples (warned with View Layer "
             "> Samples)", ("USE", "BOUNDED", "IGNORE"), warns=False),
    _ignored("view_layer.samples", "View Layer > Override > Samples",
             "DRT renders every view layer with its own Samples", 0,
             when=("scene.cycles.use_layer_samples", ("USE", "BOUNDED"))),
    _s("scene.cycles.use_animated_seed", "Sampling > Advanced > Use Animated Seed", READ,
       "DRT takes a seed of its own for every frame (and subframe), as Cycles does: the "
       "noise changes from frame to frame"),
    _ignored("scene.cycles.sampling_pattern", "Sampling > Advanced > Pattern",
             f"DRT uses its own Sampler; {NOISE_ONLY}", ("AUTOMATIC", "TABULATED_SOBOL")),
    _ignored("scene.cycles.scrambling_distance", "Sampling > Advanced > Scrambling "
             "Distance", f"DRT never correlates pixels' samples; {NOISE_ONLY}", 1.0),
    _ignored("scene.cycles.auto_scrambling_distance", "Sampling > Advanced > Automatic "
             "Scrambling Distance", f"DRT never correlates pixels' samples; {NOISE_ONLY}",
             False),
    _ignored("scene.cycles.min_light_bounces", "Sampling > Advanced > Min Light Bounces",
             "DRT plays Cycles' Russian roulette (a path goes on with probability "
             "min(sqrt(max throughput), 1), decided after the emission its next ray "
             "finds) from the third bounce on, as Min Light Bounces 2 would; "
             f"{NOISE_ONLY}", 0),
    _ignored("scene.cycles.min_transparent_bounces", "Sampling > Advanced > Min "
             "Transparent Bounces", f"DRT does not play Russian roulette on transparent "
             f"bounces; {NOISE_ONLY}", 0),
    _ignored("scene.cycles.light_sampling_threshold", "Sampling > Advanced > Light "
             "Threshold", f"DRT never skips a light sample; {NOISE_ONLY}", 0.01),
    _s("scene.cycles.use_light_tree", "Sampling > Lights > Light Tree", READ,
       "DRT picks the light to sample for each shading point with Cycles' light tree, or, "
       "when it is off, as Cycles' light distribution does: every lamp and the world "
       "alike, emissive triangles by area"),
    _ignored("scene.cycles.direct_light_sampling_type", "Sampling > Advanced > Direct Light "
             "Sampling", f"DRT combines light and BSDF sampling with multiple importance "
             f"sampling; {NOISE_ONLY}", "MULTIPLE_IMPORTANCE_SAMPLING"),
    _ignored("scene.cycles.use_guiding", "Sampling > Path Guiding",
             f"DRT does not guide paths; {NOISE_ONLY}", False),
    *_part_of("Sampling > Path Guiding", [
        "use_deterministic_guiding", "guiding_distribution_type",
        "guiding_directional_sampling_type", "use_surface_guiding",
        "surface_guiding_probability", "use_volume_guiding", "guiding_training_samples",
        "volume_guiding_probability", "use_guiding_direct_light", "use_guiding_mis_weights",
        "guiding_roughness_threshold"]),
    *_no_effect(["volume_step_rate", "volume_max_steps"], _NULL_SCATTERING),
    _ignored("scene.cycles.volume_biased", "Volumes > Biased", _NULL_SCATTERING, False),
    _ignored("scene.render.simplify_volumes", "Simplify > Volume Resolution", _NO_VOLUMES,
             1.0, when=_SIMPLIFY),
    _ignored("scene.cycles.use_fast_gi", "Light Paths > Fast GI Approximation",
             "DRT traces full global illumination", False),
    *_part_of("Light Paths > Fast GI Approximation", ["fast_gi_method",
              "ao_bounces_render"]),
    *_part_of("Light Paths > Fast GI Approximation", ["use_ao"], prefix="view_layer"),
    _ignored("scene.cycles.film_transparent_glass", "Film > Transparent > Transparent Glass",
             "DRT keeps glass opaque over the transparent background", False,
             when=("scene.render.film_transparent", (True,))),
    _ignored("scene.cycles.film_transparent_roughness", "Film > Transparent > Roughness "
             "Threshold", "part of Transparent Glass (warned there)", 0.1, warns=False),
    _ignored("scene.cycles.rolling_shutter_type", "Motion Blur > Rolling Shutter",
             "DRT exposes the whole image over the same shutter", "NONE",
             when=("scene.render.use_motion_blur", (True,))),
    _ignored("scene.cycles.rolling_shutter_duration", "Motion Blur > Rolling Shutter "
             "Duration", "part of Rolling Shutter (warned there)", 0.1, warns=False),
    _ignored("scene.cycles.texture_limit_render", "Simplify > Render > Texture Limit",
             "DRT reads textures at their full resolution", "OFF", when=_SIMPLIFY),
    _ignored("scene.cycles.use_camera_cull", "Simplify > Culling > Camera Culling",
             "DRT keeps every object", False, when=_SIMPLIFY),
    _ignored("scene.cycles.use_distance_cull", "Simplify > Culling > Distance Culling",
             "DRT keeps every object", False, when=_SIMPLIFY),
    *_part_of("Simplify > Culling", ["camera_cull_margin", "distance_cull_margin"]),
    _s("scene.cycles.dicing_rate", "Subdivision > Dicing Rate Render", READ,
       "DRT dices displaced meshes with Adaptive Subdivision to it (export.dicing)"),
    _s("scene.cycles.preview_dicing_rate", "Subdivision > Dicing Rate Viewport", READ,
       "the Rendered viewport dices displaced meshes with Adaptive Subdivision to it"),
    _s("scene.cycles.max_subdivisions", "Subdivision > Max Subdivisions", READ,
       "DRT cuts an edge of the cage into at most 2 ** it segments, as Cycles"),
    _s("scene.cycles.offscreen_dicing_scale", "Subdivision > Offscreen Scale", READ,
       "DRT dices off-screen parts coarser by it, as Cycles"),
    _s("scene.cycles.dicing_camera", "Subdivision > Dicing Camera", READ,
       "DRT dices as seen from it (the scene's camera without one)"),
    _ignored("scene.cycles.shading_system", "Render > Open Shading Language",
             "DRT runs no OSL: Script nodes are skipped", False),
    _ignored("scene.render.hair_type", "Curves > Shape",
             "DRT draws hair as 3D Curves (round tubes, Embree's round Catmull-Rom "
             "curves), not as flat ribbons", "STRAND"),
    _ignored("scene.render.hair_subdiv", "Curves > Curve Subdivisions",
             "part of Curves > Shape Ribbons (warned there)", 0, warns=False),
    _ignored("scene.render.use_freestyle", "Freestyle", "DRT draws no Freestyle lines", False),
    _ignored("scene.render.use_multiview", "Stereoscopy",
             "DRT renders the active camera's single view for every view", False),
    *_part_of("Stereoscopy", ["views_format", "use_spherical_stereo"],
              prefix="scene.render"),
    *_part_of("Freestyle", ["use_freestyle"], prefix="view_layer"),
    *[_s(f"view_layer.use_pass_cryptomatte_{kind}", f"Passes > Cryptomatte > {kind.title()}",
         READ, f"written: Crypto{kind.title()}00, 01, ... with the manifest in the metadata "
         "(Blender's Cryptomatte node picks mattes from them); coverage from the first 16 "
         "camera samples of each pixel") for kind in ("object", "material", "asset")],
    _s("view_layer.pass_cryptomatte_depth", "Passes > Cryptomatte > Levels", READ,
       "read: the names kept per pixel"),
    _s("view_layer.use_pass_cryptomatte_accurate", "Passes > Cryptomatte > Accurate",
       NO_EFFECT, "DRT's Cryptomatte always ranks every name of a pixel's samples"),
    _s("view_layer.material_override", "View Layer > Override > Material", READ,
       "read: every object renders with it, in each of its slots, as in Cycles"),
    _s("view_layer.world_override", "View Layer > Override > World", READ,
       "read: it replaces the scene's World (surface, volume and mist)"),
    _ignored("view_layer.use_solid", "View Layer > Filter > Surfaces",
             "DRT renders the surfaces anyway", True),
    _ignored("view_layer.use_sky", "View Layer > Filter > Environment",
             "DRT renders the World anyway", True),
    _s("view_layer.use_strand", "View Layer > Filter > Curves", READ,
       "read: off, no hair is drawn (particle hair and Curves objects), as in Cycles"),
    _ignored("view_layer.use_volumes", "View Layer > Filter > Volumes", _NO_VOLUMES, True,
             warns=False),
    _ignored("view_layer.use_motion_blur", "View Layer > Filter > Motion Blur",
             "DRT blurs this view layer as the scene's Motion Blur says", True,
             when=("scene.render.use_motion_blur", (True,))),
    _ignored("view_layer.pass_alpha_threshold", "View Layer > Filter > Alpha Threshold",
             "DRT's Depth and Normal passes take the first surface hit, whatever its alpha",
             0.5, when=("view_layer.use_pass_z", (True,))),
    _s("view_layer.cycles.use_denoising", "View Layer > Denoising", READ,
       "off: this view layer is not denoised, as in Cycles"),
    _s("view_layer.aovs", "View Layer > Shader AOV", READ,
       "written: what the materials' AOV Output nodes say at the first hits (a Color AOV "
       "as RGB and the share of samples that wrote it, a Value AOV as one value)"),
    _s("view_layer.lightgroups", "View Layer > Light Groups", READ,
       "written: a Combined_<group> pass per group, the light of the lamps, emissive "
       "objects and world in it (Object and World > Light Group)"),
    *[_ignored(path, f"Passes > {label}", _PASSES_HOW, False, group="passes")
      for path, label in _UNWRITTEN_PASSES],
    # -- speed, memory, the viewport or baking: never the final image
    *[_s(f"scene.cycles.{name}", label, NO_EFFECT, how) for name, label, how in [
        ("device", "Device", "DRT runs on the CPU"),
        ("use_auto_tile", "Performance > Memory > Use Tiling", "DRT's memory is bounded by "
         "its work units"),
        ("tile_size", "Performance > Memory > Tile Size", "not read"),
        ("debug_use_spatial_splits", "Performance > Acceleration Structure", "DRT uses "
         "Embree with its own settings"),
        ("preview_samples", "Sampling > Viewport > Max Samples", "the Rendered viewport's "
         "samples (0: no limit), as in Cycles (drt_addon.viewport)"),
        ("use_preview_denoising", "Sampling > Viewport > Denoise", "the Rendered viewport "
         "is denoised with OpenImageDenoise, as in Cycles"),
        ("preview_denoising_input_passes", "Sampling > Viewport > Denoise > Passes",
         "the viewport denoiser's inputs"),
        ("preview_denoising_prefilter", "Sampling > Viewport > Denoise > Prefilter",
         "the viewport denoiser's prefilter"),
        ("preview_denoising_quality", "Sampling > Viewport > Denoise > Quality",
         "the viewport denoiser's quality"),
        ("preview_denoising_start_sample", "Sampling > Viewport > Denoise > Start Sample",
         "the viewport is denoised from this sample on"),
        ("texture_limit", "Simplify > Viewport > Texture Limit", "not read: the Rendered "
         "viewport uses full-size textures"),
        ("bake_type", "Bake", "DRT does not bake"),
    ]],
    _s("scene.cycles.preview_pause", "Viewport > Pause (the 3D view header)", NO_EFFECT,
       "the Rendered viewport stops tracing and keeps its image, as in Cycles"),
    *_no_effect(["preview_denoiser", "preview_denoising_use_gpu",
                 "preview_scrambling_distance", "use_preview_adaptive_sampling",
                 "preview_adaptive_threshold", "preview_adaptive_min_samples",
                 "volume_preview_step_rate", "ao_bounces"],
                "viewport only, not read (DRT's Rendered viewport denoises with "
                "OpenImageDenoise on the CPU, samples every pixel alike and renders volumes "
                "as the final render does)"),
    *_no_effect(["debug_bvh_type", "debug_use_hair_bvh", "debug_use_compact_bvh",
                 "debug_bvh_time_steps", "debug_use_cpu_avx2", "debug_use_cpu_sse42",
                 "debug_bvh_layout", "debug_use_cuda_adaptive_compile",
                 "debug_use_optix_debug", "debug_use_hip_adaptive_compile",
                 "debug_use_metal_adaptive_compile"],
                "Cycles' debugging and devices; DRT uses Embree on the CPU"),
    _s("scene.render.threads_mode", "Performance > Threads", NO_EFFECT,
       "speed only: DRT's own Threads setting (Sampling) decides; at 0, Fixed (or "
       "`blender -t N`) gives DRT that many threads"),
    _s("scene.render.use_persistent_data", "Performance > Final Render > Persistent Data",
       NO_EFFECT, "DRT exports the scene for every render"),
    _s("scene.render.filter_size", "Film > Filter Size (EEVEE, Workbench)", NO_EFFECT,
       "not Cycles' setting; DRT's own Width decides"),
]
