"""Memory is bounded by the work-unit size, never by samples x pixels."""
import tracemalloc

from engine import RenderSettings, render
from engine_scenes import cornell_box


def _peak_bytes(samples, chunk_paths=4096):
    scene = cornell_box(48, 48)
    tracemalloc.start()
    try:
        render(scene, RenderSettings(samples=samples, chunk_paths=chunk_paths, threads=1))
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_peak_memory_does_not_grow_with_samples():
    few, many = _peak_bytes(16), _peak_bytes(256)
    print(f"peak traced memory: {few / 1e6:.1f} MB at 16 spp, {many / 1e6:.1f} MB at 256 spp")
    # 16x the samples: the work grows 16-fold, the memory must not (allow 25% slack)
    assert many < 1.25 * few


def test_peak_memory_follows_the_chunk_size():
    small, large = _peak_bytes(8, chunk_paths=1024), _peak_bytes(8, chunk_paths=16384)
    assert large > 2 * small      # the chunk, not the image, is what memory scales with
