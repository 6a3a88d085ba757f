"""Errors and warnings raised while exporting a Blender scene."""


class ExportError(Exception):
    """A scene DRT cannot render, with a message meant for the user."""


class Reporter:
    """Collects warnings, saying each one once (per material, per light...)."""

    def __init__(self, report=None):
        self._report = report
        self.warnings = []
        self._seen = set()

    def warn(self, message: str, key=None):
        key = key or message
        if key in self._seen:
            return
        self._seen.add(key)
        self.warnings.append(message)
        if self._report is not None:
            self._report({"WARNING"}, message)
