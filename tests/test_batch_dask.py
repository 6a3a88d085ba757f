"""The batch renderer on a real dask.distributed LocalCluster of two worker processes
(one for the module: workers importing bpy take seconds to start): frames rendered on
the cluster equal the single-machine render with the same seed; a frame split into
sample batches and merged equals the render of all its samples at once (sample counts
bit-exact, sums within float64 rounding); a worker killed mid-job loses no frame."""
import os

import numpy as np
import pytest

from batch_scenes import FRAMES, build_animated_cornell
from conftest import read_image_linear


@pytest.fixture(scope="module")
def anim_blend(bpy_drt, tmp_path_factory):
    return build_animated_cornell(bpy_drt, tmp_path_factory.mktemp("dask") / "anim.blend")


@pytest.fixture(scope="module")
def cluster(anim_blend):
    from drt_addon.dask_jobs import connect
    client, local = connect(workers=2)
    yield client, local
    client.close()
    local.close()


def drt(*args):
    from drt_addon.batch import main
    return main(["render", *map(str, args)])


@pytest.fixture(scope="module")
def single_machine(bpy_drt, anim_blend, tmp_path_factory):
    """Frames 1..3 rendered here through Blender's pipeline, as scene-linear EXR."""
    out = tmp_path_factory.mktemp("single")
    assert drt(anim_blend, "-o", out / "f_#.exr", "--frames", "1-3", "--no-progress") == 0
    return {f: read_image_linear(bpy_drt, str(out / f"f_{f}.exr")) for f in FRAMES}


def test_a_frame_range_on_the_cluster_equals_the_single_machine_render(
        bpy_drt, anim_blend, cluster, single_machine, tmp_path, capsys):
    client, local = cluster
    code = drt(anim_blend, "-o", tmp_path / "f_#.exr", "--frames", "1-3",
               "--cluster", local.scheduler_address, "--no-progress")
    out, err = capsys.readouterr()
    assert code == 0, err
    assert sorted(os.listdir(tmp_path)) == [f"f_{f}.exr" for f in FRAMES]
    for f in FRAMES:
        assert np.array_equal(read_image_linear(bpy_drt, str(tmp_path / f"f_{f}.exr")),
                              single_machine[f]), f"frame {f}"
    header = next(l for l in out.splitlines() if l.split()[:1] == ["frame"])
    assert "worker" in header                 # the summary says where frames rendered


def _film_of(client, blend, frame, ranges):
    from drt_addon.dask_jobs import file_stamp, merge_parts, render_part
    from drt_addon.overrides import Overrides
    futures = [client.submit(render_part, blend, file_stamp(blend), frame, Overrides(), a, b,
                             pure=False) for a, b in ranges]
    return merge_parts(client.gather(futures))


def test_sample_batches_merge_into_the_whole_render(bpy_drt, anim_blend, cluster,
                                                    single_machine, tmp_path, capsys):
    client, _ = cluster
    whole = _film_of(client, anim_blend, 2, [(0, 4)])
    merged = _film_of(client, anim_blend, 2, [(0, 1), (1, 3), (3, 4)])
    assert np.array_equal(merged.count, whole.count) and whole.count.min() > 0
    # float64 sums added in another order: equal to rounding (measured: at most a few
    # ulp, ~1e-16 relative)
    for name in ("sum", "sum_sq", "alpha_sum"):
        a, b = getattr(merged, name), getattr(whole, name)
        assert np.allclose(a, b, rtol=1e-13, atol=1e-300), name
    assert np.abs(merged.variance_of_mean() - whole.variance_of_mean()).max() < 1e-12
    # control: the same two samples twice are not samples 0..3
    twice = _film_of(client, anim_blend, 2, [(0, 2), (0, 2)])
    assert np.array_equal(twice.count, whole.count)
    assert not np.allclose(twice.sum, whole.sum, rtol=1e-3)

    # and through the command line: the written frame equals the single-machine one
    code = drt(anim_blend, "-o", tmp_path / "b_#.exr", "--frame", "2", "--sample-batches",
               "3", "--cluster", client.scheduler.address, "--no-progress")
    assert code == 0, capsys.readouterr().err
    split = read_image_linear(bpy_drt, str(tmp_path / "b_2.exr"))
    assert np.allclose(split, single_machine[2], rtol=1e-6, atol=1e-7)


def _die_in_the_next_render():
    """Run on one worker: its next task's engine.render ends the process at once, as a
    crashed or killed machine would, while that task is running."""
    from drt_addon.engine_link import engine

    def exit_now(*args, **kwargs):
        os._exit(1)

    engine.render = exit_now


def test_a_killed_worker_loses_no_frame(bpy_drt, anim_blend, cluster, single_machine,
                                        tmp_path):
    import bpy

    from drt_addon.batch import plan_outputs
    from drt_addon.dask_jobs import render_frames
    from drt_addon.overrides import Overrides
    client, _ = cluster
    bpy.ops.wm.open_mainfile(filepath=anim_blend, load_ui=False)
    scene = bpy.context.scene
    jobs, _ = plan_outputs(bpy, scene, str(tmp_path / "k_#.exr"), list(FRAMES))
    victim = sorted(client.scheduler_info()["workers"])[0]
    client.run(_die_in_the_next_render, workers=[victim])
    results = render_frames(client, bpy, scene, anim_blend, jobs, Overrides(),
                            sample_batches=4, retries=1)
    assert victim not in client.scheduler_info()["workers"]     # it did die
    assert sorted(r.frame for r in results) == list(FRAMES)
    assert sorted(os.listdir(tmp_path)) == [f"k_{f}.exr" for f in FRAMES]
    for f in FRAMES:
        image = read_image_linear(bpy_drt, str(tmp_path / f"k_{f}.exr"))
        assert np.allclose(image, single_machine[f], rtol=1e-6, atol=1e-7), f"frame {f}"


def test_an_unreachable_scheduler_is_a_clear_error():
    from drt_addon.dask_jobs import ClusterError, connect
    with pytest.raises(ClusterError, match="cannot reach the scheduler tcp://127.0.0.1:1"):
        connect(address="tcp://127.0.0.1:1", timeout=1)


def test_sample_ranges_cover_every_sample_once():
    from drt_addon.dask_jobs import sample_ranges
    assert sample_ranges(10, 3) == [(0, 3), (3, 6), (6, 10)]
    assert sample_ranges(2, 8) == [(0, 1), (1, 2)]          # never an empty range
    assert sample_ranges(7, 1) == [(0, 7)]
