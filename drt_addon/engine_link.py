"""The one place that finds the tracer package.

Installed as a Blender extension, the repository root is the package
(`bl_ext.<repo>.drt`) and the tracer is its sibling subpackage `..engine`. Run from a
source checkout (tests, `python -m drt_addon`), `drt_addon` is a top-level package and
the tracer is the top-level package `engine`.
"""
try:
    from .. import engine  # noqa: F401  (extension layout)
except ImportError:
    import engine  # noqa: F401  (source checkout: the repository root is on sys.path)
