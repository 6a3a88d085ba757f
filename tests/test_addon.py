"""The add-on registers, DRT is a render engine Blender can select, and it unregisters
cleanly."""
import os
import subprocess
import sys

from conftest import ROOT


def _engine_ids(bpy):
    """bl_idnames of the render engines currently registered with Blender."""
    return {getattr(cls, "bl_idname", None) for cls in bpy.types.RenderEngine.__subclasses__()
            if cls.is_registered}


def test_drt_is_a_registered_render_engine(bpy_drt):
    bpy = bpy_drt
    assert "DRT" in _engine_ids(bpy)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    assert scene.render.engine == "DRT"
    assert scene.drt.samples >= 1
    # The engine declares Blender 4.4's constructor contract.
    from drt_addon.render_engine import DRTRenderEngine
    assert DRTRenderEngine.bl_label == "DRT"
    assert DRTRenderEngine.bl_use_shading_nodes_custom is False


_LAZY = """
import sys
sys.path.insert(0, {root!r})
import bpy
import drt_addon
drt_addon.register()
loaded = lambda: sorted(m for m in ("engine", "numba", "engine.embree", "embreex",
                                   "drt_addon.export") if m in sys.modules)
print("registered:", loaded())
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.render.resolution_x = scene.render.resolution_y = 8
scene.cycles.samples = 1
bpy.ops.mesh.primitive_cube_add()
bpy.ops.object.camera_add(location=(0.0, -6.0, 0.0), rotation=(1.5708, 0.0, 0.0))
scene.camera = bpy.context.object
bpy.ops.render.render()
print("after a Cycles render:", loaded())
scene.render.engine = "DRT"
scene.drt.samples = 1
bpy.ops.render.render()
print("after a DRT render:", loaded())
"""


def test_registering_drt_loads_no_tracer_until_it_renders():
    """Principle 3: a Blender with DRT enabled that renders with Cycles pays nothing for
    DRT's tracer (NumPy kernels compiled by Numba, Embree, the export): they load on the
    first DRT render. embreex's Python binding never loads: DRT calls Embree's C API."""
    out = subprocess.run([sys.executable, "-c", _LAZY.format(root=ROOT)], cwd=ROOT,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = [l for l in out.stdout.splitlines() if l.startswith(("registered", "after"))]
    assert lines == ["registered: []", "after a Cycles render: []",
                     "after a DRT render: ['drt_addon.export', 'engine', 'engine.embree', 'numba']"]


def test_unregister_and_register_again(bpy_drt):
    bpy = bpy_drt
    import drt_addon
    drt_addon.unregister()
    try:
        assert "DRT" not in _engine_ids(bpy)
        assert not hasattr(bpy.types.Scene, "drt")
        bpy.ops.wm.read_factory_settings(use_empty=True)
        try:
            bpy.context.scene.render.engine = "DRT"
            engine_after = bpy.context.scene.render.engine
        except TypeError:
            engine_after = None
        assert engine_after != "DRT"
    finally:
        drt_addon.register()
    assert hasattr(bpy.types.Scene, "drt")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.context.scene.render.engine = "DRT"
    assert bpy.context.scene.render.engine == "DRT"


def test_blender_panels_are_shared_with_drt(bpy_drt):
    bpy = bpy_drt
    # Blender's own camera panels, which Cycles shares, list DRT as compatible ...
    assert "DRT" in bpy.types.DATA_PT_lens.COMPAT_ENGINES
    assert "DRT" in bpy.types.DATA_PT_camera_dof.COMPAT_ENGINES
    # ... and DRT's own settings panels are registered for the render tab.
    from drt_addon import ui
    for cls in ui.CLASSES:
        assert cls.is_registered
        assert cls.bl_context in ("render", "view_layer")
    assert ui.DRT_PT_passes.bl_context == "view_layer"
    assert "DRT" not in bpy.types.VIEWLAYER_PT_freestyle.COMPAT_ENGINES


def _recording_layout(drawn: list):
    """A stand-in for a panel's layout that records each (data, property) drawn."""
    class Layout:
        use_property_split = False
        active = True

        def column(self, **kw):
            return self

        def prop(self, data, name, **kw):
            drawn.append((data, name))

        def label(self, **kw):
            drawn.append(("label", kw.get("text")))
    return Layout


def test_light_paths_panel_edits_the_files_cycles_settings(bpy_drt):
    """DRT's Light Paths panel draws Cycles' own properties, which DRT renders with (one
    vocabulary): what an artist sets there is what Cycles uses too."""
    import types
    from drt_addon import ui
    scene = bpy_drt.context.scene
    drawn = []
    Layout = _recording_layout(drawn)
    ui.DRT_PT_light_paths.draw(types.SimpleNamespace(layout=Layout()),
                               types.SimpleNamespace(scene=scene))
    assert [d for d, _ in drawn] == [scene.cycles] * len(drawn)
    assert [n for _, n in drawn][:8] == [
        "max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
        "volume_bounces", "transparent_max_bounces", "sample_clamp_direct",
        "sample_clamp_indirect"]


def test_denoise_panel_shows_the_files_cycles_denoise_settings(bpy_drt):
    """Sampling > Denoise in DRT's panels draws Cycles' own Denoise settings, which DRT
    denoises with (drt_addon.denoise), its switch in the header."""
    import types
    from drt_addon import ui
    scene = bpy_drt.context.scene
    drawn = []
    Layout = _recording_layout(drawn)
    context = types.SimpleNamespace(scene=scene, engine="DRT")
    panel = types.SimpleNamespace(layout=Layout())
    assert ui.DRT_PT_denoise.poll(context)
    assert ui.DRT_PT_denoise.bl_parent_id == "DRT_PT_sampling"
    ui.DRT_PT_denoise.draw_header(panel, context)
    ui.DRT_PT_denoise.draw(panel, context)
    assert drawn == [(scene.cycles, n) for n in (
        "use_denoising", "denoiser", "denoising_input_passes", "denoising_prefilter",
        "denoising_quality")]


def test_viewport_panel_shows_the_files_cycles_viewport_settings(bpy_drt):
    """Sampling > Viewport draws Cycles' own viewport samples and denoiser, which DRT's
    Rendered viewport renders with (drt_addon.viewport); the engine has the viewport's
    methods, so Blender's Rendered mode is DRT's, not EEVEE's."""
    import types
    from drt_addon import ui
    from drt_addon.render_engine import DRTRenderEngine
    scene = bpy_drt.context.scene
    drawn = []
    Layout = _recording_layout(drawn)
    context = types.SimpleNamespace(scene=scene, engine="DRT")
    assert ui.DRT_PT_viewport.poll(context)
    ui.DRT_PT_viewport.draw(types.SimpleNamespace(layout=Layout()), context)
    assert drawn == [(scene.cycles, n) for n in (
        "preview_samples", "use_preview_denoising", "preview_denoising_input_passes",
        "preview_denoising_prefilter", "preview_denoising_quality",
        "preview_denoising_start_sample")]
    assert callable(DRTRenderEngine.view_update) and callable(DRTRenderEngine.view_draw)
    # the 3D view header's pause button, in Rendered shading with DRT only
    assert ui.draw_pause in bpy_drt.types.VIEW3D_HT_header._dyn_ui_initialize()
    for engine, shading, shown in (("DRT", "RENDERED", True), ("DRT", "SOLID", False),
                                   ("CYCLES", "RENDERED", False)):
        drawn.clear()
        space = types.SimpleNamespace(shading=types.SimpleNamespace(type=shading))
        ui.draw_pause(types.SimpleNamespace(layout=Layout()), types.SimpleNamespace(
            scene=scene, engine=engine, space_data=space))
        assert drawn == ([(scene.cycles, "preview_pause")] if shown else []), engine


def test_manifest_is_a_valid_extension_manifest():
    import tomllib
    with open(os.path.join(ROOT, "blender_manifest.toml"), "rb") as f:
        m = tomllib.load(f)
    assert m["schema_version"] == "1.0.0"
    assert m["id"] == "drt" and m["type"] == "add-on"
    assert m["blender_version_min"] == "4.2.0"
    assert "SPDX:GPL-3.0-or-later" in m["license"]
    assert "linux-x64" in m["platforms"]
    # The package root is the manifest's folder: __init__.py with register/unregister.
    src = open(os.path.join(ROOT, "__init__.py")).read()
    assert "from .drt_addon import register, unregister" in src


def test_engine_never_imports_bpy():
    engine_dir = os.path.join(ROOT, "engine")
    offenders = []
    for base, _, files in os.walk(engine_dir):
        for name in files:
            if name.endswith(".py"):
                text = open(os.path.join(base, name)).read()
                if "import bpy" in text or "from bpy" in text:
                    offenders.append(name)
    assert offenders == []


def test_addon_imports_are_relative():
    """Inside an installed extension only relative imports resolve."""
    bad = []
    for base, _, files in os.walk(os.path.join(ROOT, "drt_addon")):
        for name in files:
            if not name.endswith(".py"):
                continue
            for line in open(os.path.join(base, name)):
                s = line.strip()
                if s.startswith(("from drt_addon", "import drt_addon", "from engine",
                                 "import engine ")):
                    bad.append(f"{name}: {s}")
    # engine_link.py is the single documented fallback for the source checkout
    bad = [b for b in bad if not b.startswith("engine_link.py")]
    assert bad == []
