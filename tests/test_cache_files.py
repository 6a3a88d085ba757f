"""engine/kernels/cache_files.py: which CPU's compiled code a process may load, and cache
pickles read under whatever name the engine package has. (End to end: the extension zip's
shipped kernels load in `bl_ext.user_default.drt.engine`, tests/test_extension_package.py.)"""
from __future__ import annotations

import pickle
import sys
import types

import pytest

from engine.kernels import cache_files as cf
from engine.kernels.cache_files import X86_64_LEVELS, compatible

TRIPLE = "x86_64-unknown-linux-gnu"
HOST = (TRIPLE, "znver3", "+avx,+avx2,+fma")
V3_HOST = set(X86_64_LEVELS["x86-64-v3"]) | {"sse", "sse2"}
OLD_HOST = set(X86_64_LEVELS["x86-64-v2"]) | {"sse", "sse2"}       # no AVX


def test_generic_code_runs_on_every_cpu_of_its_triple():
    assert compatible((TRIPLE, "generic", ""), HOST, set())
    assert not compatible(("x86_64-pc-windows-msvc", "generic", ""), HOST, V3_HOST)


def test_a_tier_runs_where_the_cpu_has_all_its_instructions():
    v3 = (TRIPLE, "x86-64-v3", ",".join("+" + f for f in X86_64_LEVELS["x86-64-v3"]))
    assert compatible(v3, HOST, V3_HOST)
    assert not compatible(v3, HOST, OLD_HOST)
    # the level's name alone implies its instructions
    assert not compatible((TRIPLE, "x86-64-v3", ""), HOST, OLD_HOST)
    assert compatible((TRIPLE, "x86-64-v2", ""), HOST, OLD_HOST)


def test_code_for_another_named_cpu_is_refused():
    """A CPU name implies instructions the feature list does not spell out."""
    assert not compatible((TRIPLE, "skylake-avx512", "+avx2"), HOST, V3_HOST | {"avx512f"})
    assert compatible((TRIPLE, "znver3", "+avx2"), HOST, V3_HOST)      # the host's own name
    assert not compatible((TRIPLE, "znver3", "+avx512f"), HOST, V3_HOST)


class _Record:
    """Pickled by reference, like the engine's classes in Numba's cache."""


def test_engine_modules_are_read_as_this_package(monkeypatch):
    """A pickle that names `engine.x` (built in a source checkout) loads where the engine
    is installed under another name (`bl_ext.<repo>.drt.engine`)."""
    assert cf.ENGINE_PACKAGE == "engine"          # this checkout
    installed = "bl_fake.user_default.drt.engine"
    parts = (installed + ".kernels.records").split(".")
    for n in range(1, len(parts) + 1):
        monkeypatch.setitem(sys.modules, ".".join(parts[:n]),
                            types.ModuleType(".".join(parts[:n])))
    sys.modules[installed + ".kernels.records"].Record = _Record
    monkeypatch.setattr(cf, "ENGINE_PACKAGE", installed)
    data = b"cengine.kernels.records\nRecord\n."  # a class pickled by reference
    with pytest.raises(ImportError):
        pickle.loads(data)                        # no module engine.kernels.records
    assert cf.relocating_loads(data) is _Record
    assert cf.canonical_module("engine") == installed
    assert cf.canonical_module("numba.core.types") == "numba.core.types"
    assert cf.canonical_module("engineering") == "engineering"
    # what another copy of the add-on saved: a legacy add-on, another extension repository
    assert cf.canonical_module("drt.engine.kernels.records") == installed + ".kernels.records"
    assert (cf.canonical_module("bl_ext.studio_repo.drt.engine.kernels.records")
            == installed + ".kernels.records")
    assert cf.relocating_loads(b"cdrt.engine.kernels.records\nRecord\n.") is _Record
    assert cf.canonical_module("other.engine.kernels") == "other.engine.kernels"


@pytest.mark.parametrize("tier", ["generic", "x86-64-v3"])
def test_tier_environment_compiles_for_that_tier(tier):
    env = cf.tier_environment(tier)
    assert env["NUMBA_CPU_NAME"] == tier
    if tier == "generic":
        assert "NUMBA_CPU_FEATURES" not in env     # Numba then uses no features
    else:
        assert set(env["NUMBA_CPU_FEATURES"].split(",")) == {
            "+" + f for f in X86_64_LEVELS[tier]}
