"""Render Properties panels for DRT, and DRT added to Blender's own Camera, Light,
Material and World panels (the way Cycles' add-on does), so users edit the usual fields."""
import bpy

ENGINE = "DRT"


class DRTPanel:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES


class DRT_PT_sampling(DRTPanel, bpy.types.Panel):
    bl_label = "Sampling"

    def draw(self, context):
        s = context.scene.drt
        col = self.layout.column()
        col.use_property_split = True
        col.prop(s, "use_adaptive_sampling")
        sub = col.column()
        sub.active = s.use_adaptive_sampling
        sub.prop(s, "adaptive_threshold")
        col.prop(s, "samples", text="Max Samples" if s.use_adaptive_sampling else "Samples")
        sub = col.column()
        sub.active = s.use_adaptive_sampling
        sub.prop(s, "adaptive_min_samples")
        col.prop(s, "time_limit")
        col.prop(s, "sampler")
        cycles = getattr(context.scene, "cycles", None)
        if cycles is not None:                 # the file's own seed, as in Cycles
            row = col.row(align=True)
            row.prop(cycles, "seed")
            row.prop(cycles, "use_animated_seed", text="", icon="TIME")
            col.prop(cycles, "use_light_tree")   # Sampling > Lights > Light Tree, Cycles'
        col.prop(s, "integrator")
        col.prop(s, "threads")


class CyclesSettingsPanel(DRTPanel):
    """A sub-panel of Sampling that draws Cycles' own settings (scene.cycles): shown
    where the Cycles add-on is on."""
    bl_parent_id = "DRT_PT_sampling"

    @classmethod
    def poll(cls, context):
        return super().poll(context) and hasattr(context.scene, "cycles")


class DRT_PT_denoise(CyclesSettingsPanel, bpy.types.Panel):
    """Render > Denoise: Cycles' own settings (scene.cycles), which DRT renders with
    (drt_addon.denoise)."""
    bl_label = "Denoise"

    def draw_header(self, context):
        self.layout.prop(context.scene.cycles, "use_denoising", text="")

    def draw(self, context):
        cycles = context.scene.cycles
        col = self.layout.column()
        col.use_property_split = True
        col.active = cycles.use_denoising
        col.prop(cycles, "denoiser")
        col.prop(cycles, "denoising_input_passes", text="Passes")
        sub = col.column()
        sub.active = cycles.denoising_input_passes != "RGB"
        sub.prop(cycles, "denoising_prefilter", text="Prefilter")
        if hasattr(cycles, "denoising_quality"):               # Blender 4.1+
            col.prop(cycles, "denoising_quality", text="Quality")


class DRT_PT_viewport(CyclesSettingsPanel, bpy.types.Panel):
    """Sampling > Viewport: the Rendered viewport's samples and denoiser, Cycles' own
    settings (scene.cycles), which DRT's viewport renders with (drt_addon.viewport)."""
    bl_label = "Viewport"

    def draw(self, context):
        cycles = context.scene.cycles
        col = self.layout.column()
        col.use_property_split = True
        col.prop(cycles, "preview_samples", text="Max Samples")
        col.prop(cycles, "use_preview_denoising", text="Denoise")
        sub = col.column()
        sub.active = cycles.use_preview_denoising
        sub.prop(cycles, "preview_denoising_input_passes", text="Passes")
        sub.prop(cycles, "preview_denoising_prefilter", text="Prefilter")
        if hasattr(cycles, "preview_denoising_quality"):       # Blender 4.1+
            sub.prop(cycles, "preview_denoising_quality", text="Quality")
        sub.prop(cycles, "preview_denoising_start_sample", text="Start Sample")


class DRT_PT_light_paths(DRTPanel, bpy.types.Panel):
    bl_label = "Light Paths"

    def draw(self, context):
        """The file's Cycles settings themselves (`scene.cycles`), which DRT renders with:
        one vocabulary for both engines (properties.CYCLES_SHARED)."""
        cycles = getattr(context.scene, "cycles", None)
        if cycles is None:
            self.layout.label(text="Enable the Cycles add-on to edit these (DRT uses "
                                   "Cycles' defaults)")
            return
        col = self.layout.column(align=True)
        col.use_property_split = True
        for name in ("max_bounces", "diffuse_bounces", "glossy_bounces",
                     "transmission_bounces", "volume_bounces", "transparent_max_bounces"):
            col.prop(cycles, name)
        col = self.layout.column(align=True)
        col.use_property_split = True
        col.prop(cycles, "sample_clamp_direct")
        col.prop(cycles, "sample_clamp_indirect")
        col = self.layout.column(align=True)
        col.use_property_split = True
        col.prop(cycles, "blur_glossy")
        col.prop(cycles, "caustics_reflective")
        col.prop(cycles, "caustics_refractive")


class DRT_PT_film(DRTPanel, bpy.types.Panel):
    bl_label = "Film"

    def draw(self, context):
        col = self.layout.column()
        col.use_property_split = True
        cycles = getattr(context.scene, "cycles", None)
        if cycles is not None:       # the file's Film > Exposure and Pixel Filter, Cycles'
            col.prop(cycles, "film_exposure")
            col.prop(cycles, "pixel_filter_type", text="Pixel Filter")
            col.prop(cycles, "filter_width", text="Width")


class DRT_PT_passes(DRTPanel, bpy.types.Panel):
    bl_label = "Passes"
    bl_context = "view_layer"

    def draw(self, context):
        view_layer = context.view_layer
        col = self.layout.column(heading="Data", align=True)
        col.use_property_split = True
        col.prop(view_layer, "use_pass_combined")
        col.prop(view_layer, "use_pass_z")
        col.prop(view_layer, "use_pass_mist")
        col.prop(view_layer, "use_pass_normal")
        col.prop(view_layer, "use_pass_position")
        col.prop(view_layer, "use_pass_uv")
        drt = getattr(view_layer, "drt", None)
        if drt is not None:
            col.prop(drt, "use_pass_denoising_data")
            col.prop(drt, "use_pass_noise")


class DRT_PT_bake(DRTPanel, bpy.types.Panel):
    """Render > Bake: Cycles' bake type and Blender's bake settings, which DRT bakes with
    (drt_addon.bake); the button runs Blender's bake operator."""
    bl_label = "Bake"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        return super().poll(context) and hasattr(context.scene, "cycles")

    def draw(self, context):
        cycles, bake = context.scene.cycles, context.scene.render.bake
        col = self.layout.column()
        col.use_property_split = True
        col.operator("object.bake", icon="RENDER_STILL").type = cycles.bake_type
        col.prop(cycles, "bake_type")
        kind = cycles.bake_type
        if kind in ("COMBINED", "DIFFUSE", "GLOSSY", "TRANSMISSION"):
            sub = col.column(heading="Lighting", align=True)
            sub.prop(bake, "use_pass_direct")
            sub.prop(bake, "use_pass_indirect")
            if kind == "COMBINED":
                sub = col.column(heading="Contributions", align=True)
                for name in ("diffuse", "glossy", "transmission", "emit"):
                    sub.prop(bake, f"use_pass_{name}")
            else:
                sub.prop(bake, "use_pass_color")
        elif kind == "NORMAL":
            col.prop(bake, "normal_space", text="Space")
            sub = col.column(align=True)
            sub.prop(bake, "normal_r", text="Swizzle R")
            sub.prop(bake, "normal_g", text="G")
            sub.prop(bake, "normal_b", text="B")
        col.prop(bake, "use_selected_to_active")
        if bake.use_selected_to_active:
            col.prop(bake, "cage_extrusion")
            col.prop(bake, "max_ray_distance")
        col.prop(bake, "target")
        col.prop(bake, "margin")
        col.prop(bake, "use_clear", text="Clear Image")


CLASSES = (DRT_PT_sampling, DRT_PT_denoise, DRT_PT_viewport, DRT_PT_light_paths, DRT_PT_film,
           DRT_PT_passes, DRT_PT_bake)

# Blender's generic panels for what Cycles draws in panels of its own add-on: depth of
# field, light type/colour/power, spot shape, the material slots and node surfaces.
_EXTRA_PANELS = ("DATA_PT_camera_dof", "DATA_PT_camera_dof_aperture", "DATA_PT_light",
                 "DATA_PT_spot", "EEVEE_MATERIAL_PT_context_material",
                 "EEVEE_MATERIAL_PT_surface", "EEVEE_WORLD_PT_surface")


def _builtin_panels():
    for name in dir(bpy.types):
        cls = getattr(bpy.types, name, None)
        engines = getattr(cls, "COMPAT_ENGINES", None)
        module = getattr(cls, "__module__", "")
        if not isinstance(engines, set) or not module.startswith("bl_ui"):
            continue
        if module == "bl_ui.properties_freestyle":     # DRT does not render Freestyle
            continue
        if "CYCLES" in engines or name in _EXTRA_PANELS:
            yield cls


def draw_pause(self, context):
    """The 3D view header's pause button in Rendered shading, Cycles' own property
    (`scene.cycles.preview_pause`), which DRT's viewport follows (drt_addon.viewport)."""
    cycles = getattr(context.scene, "cycles", None)
    space = context.space_data
    if (context.engine == ENGINE and cycles is not None and space is not None
            and space.shading.type == "RENDERED"):
        self.layout.prop(cycles, "preview_pause", icon="PLAY", text="")


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    for panel in _builtin_panels():
        panel.COMPAT_ENGINES.add(ENGINE)
    bpy.types.VIEW3D_HT_header.append(draw_pause)


def unregister():
    bpy.types.VIEW3D_HT_header.remove(draw_pause)
    for panel in _builtin_panels():
        panel.COMPAT_ENGINES.discard(ENGINE)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
