"""The exception a node translator raises for a node or setting DRT does not evaluate
(the compiler reports it and the socket falls back to its own value)."""


class Unsupported(Exception):
    pass
