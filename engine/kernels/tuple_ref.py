"""Tuples of arrays passed between kernels by reference.

Numba passes a tuple to a compiled function that is not inlined as all of its members,
one machine argument each, and an array is seven to nine of them (its data pointer,
shape, strides, ...). The light table is 27 arrays, the geometry 14: a call that takes
one of them copies about 200 words onto the stack and back, and a path vertex makes
dozens of such calls. Measured on the Cornell box's area lamp (docs/vertex_costs.py),
picking and sampling the one lamp cost 620 ns per call with the table passed as a
tuple, 320 ns with it by reference, of which the sampling arithmetic is 110 ns; the
Cornell box's shading per path vertex went from 1866 ns to 624 ns when
path_vertex.shade began to pass its records by reference (docs/benchmarks.md,
section 1, run before and after).

`by_ref(t)` in a kernel stores the tuple `t` once in the calling function's stack frame
and gives a `TupleRef`, one pointer, that kernels index as they index the tuple:
`ref[LAMPS]`, and `ref.beta` on a named tuple. It cannot be unpacked (`a, b = ref` does
not compile), so a tuple that a callee unpacks (subsurface's `rays`) stays a tuple. The
reference is borrowed from the frame that made it: a kernel may pass it down to the
kernels it calls, never return it or store it (`BorrowingCheck` in jit.py refuses a
kernel that returns one), and the tuple's arrays must outlive it: wrap arguments and
their members, which the caller holds for the call, not arrays the kernel allocates
itself. Anything else passes through `by_ref` unchanged (None, an array), so a kernel
wraps its arguments without asking what they are.

Run as plain Python (NUMBA_DISABLE_JIT=1), `by_ref` returns the tuple itself.
"""
from __future__ import annotations

from numba.core import cgutils, types
from numba.core.datamodel import models
from numba.core.extending import (infer_getattr, intrinsic, overload, register_model)
from numba.core.imputils import impl_ret_borrowed, lower_builtin, lower_getattr_generic
from numba.core.typing.templates import AbstractTemplate, AttributeTemplate, infer, signature


class TupleRef(types.Type):
    """A pointer to a tuple (`dtype`) in a kernel's stack frame."""

    def __init__(self, dtype):
        self.dtype = dtype
        super().__init__(name=f"TupleRef({dtype})")


@register_model(TupleRef)
class TupleRefModel(models.PointerModel):
    pass


def by_ref(value):
    """`value` by reference when it is a tuple (in compiled code); itself otherwise."""
    return value


@intrinsic
def _store_in_frame(typingctx, tup):
    def codegen(context, builder, sig, args):
        model = context.data_model_manager[tup]
        ptr = cgutils.alloca_once(builder, model.get_data_type())   # in the entry block
        builder.store(model.as_data(builder, args[0]), ptr)
        return ptr
    return TupleRef(tup)(tup), codegen


@overload(by_ref, inline="always")
def _by_ref(value):
    if isinstance(value, types.BaseTuple):
        return lambda value: _store_in_frame(value)
    return lambda value: value


def _member(context, builder, ref_type, ptr, i):
    """Member i of the tuple behind ptr, as a borrowed value."""
    member_type = ref_type.dtype.types[i]
    addr = cgutils.gep_inbounds(builder, ptr, 0, i)
    value = context.data_model_manager[member_type].load_from_data_pointer(builder, addr)
    return impl_ret_borrowed(context, builder, member_type, value)


@infer
class _StaticGetItem(AbstractTemplate):
    key = "static_getitem"

    def generic(self, args, kws):
        ref, idx = args
        if isinstance(ref, TupleRef) and isinstance(idx, int):
            members = ref.dtype.types
            if -len(members) <= idx < len(members):
                return signature(members[idx], ref, types.literal(idx))


@lower_builtin("static_getitem", TupleRef, types.IntegerLiteral)
def _static_getitem(context, builder, sig, args):
    ref_type = sig.args[0]
    idx = sig.args[1].literal_value
    if idx < 0:
        idx += len(ref_type.dtype.types)
    return _member(context, builder, ref_type, args[0], idx)


@infer_getattr
class _NamedField(AttributeTemplate):
    key = TupleRef

    def generic_resolve(self, ref, attr):
        tup = ref.dtype
        if isinstance(tup, types.BaseNamedTuple) and attr in tup.fields:
            return tup.types[tup.fields.index(attr)]


@lower_getattr_generic(TupleRef)
def _named_field(context, builder, typ, value, attr):
    return _member(context, builder, typ, value, typ.dtype.fields.index(attr))
