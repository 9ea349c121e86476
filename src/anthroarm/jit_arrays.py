"""Scratch arrays in a compiled kernel's stack frame and views of arrays without reshape's
run-time layout search: Numba intrinsics (``numba.extending.intrinsic``) that :mod:`anthroarm.jit`
exports (``local``, ``local2``, ``local_flags``, ``local_ints2``, ``view2``, ``view3``, ``part``,
``part2``, ``borrow``), with the numpy form the reference (the interpreter) runs for each
(:data:`PY_FORMS`).  Part of the kernel sources (:func:`anthroarm.jit.kernel_sources_digest`):
an edit here compiles every kernel again."""

from __future__ import annotations

import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic


def _array_value(context, builder, arrty, data, shape, strides, meminfo=None, parent=None):
    """The LLVM value of a Numba array of type ``arrty`` (Numba's array data model, read through
    ``context.data_model_manager``; llvmlite's ``insert_value``)."""
    model = context.data_model_manager[arrty]
    llty = context.get_value_type(arrty)
    intp = context.get_value_type(types.intp)
    pos = model.get_field_position
    val = ir.Constant(llty, ir.Undefined)
    elem = llty.elements
    val = builder.insert_value(
        val,
        meminfo if meminfo is not None else ir.Constant(elem[pos("meminfo")], None),
        pos("meminfo"),
    )
    val = builder.insert_value(
        val, parent if parent is not None else ir.Constant(elem[pos("parent")], None), pos("parent")
    )
    itemsize = context.get_abi_sizeof(context.get_data_type(arrty.dtype))
    nitems = ir.Constant(intp, 1)
    for n in shape:
        nitems = builder.mul(nitems, n)
    val = builder.insert_value(val, nitems, pos("nitems"))
    val = builder.insert_value(val, ir.Constant(intp, itemsize), pos("itemsize"))
    val = builder.insert_value(val, data, pos("data"))
    for i, (n, s) in enumerate(zip(shape, strides)):
        val = builder.insert_value(val, n, [pos("shape"), i])
        val = builder.insert_value(val, s, [pos("strides"), i])
    return val


def _local_array(dtype, ndim: int):
    """A Numba intrinsic ``f(*shape)`` (``ndim`` literal sizes) that makes a C-order array of
    ``dtype`` in the calling kernel's stack frame (LLVM ``alloca`` in its entry block: made once
    per call, freed at its return; no heap, no reference count).  Its contents are undefined."""

    def typer(typingctx, *sizes):
        if len(sizes) != ndim or not all(isinstance(n, types.IntegerLiteral) for n in sizes):
            raise numba.errors.RequireLiteralValue(f"a local array takes {ndim} literal sizes")
        shape = [n.literal_value for n in sizes]
        arrty = types.Array(dtype, ndim, "C")

        def codegen(context, builder, sig, args):
            intp = context.get_value_type(types.intp)
            llty = context.get_data_type(dtype)
            size = context.get_abi_sizeof(llty)
            with builder.goto_entry_block():
                data = builder.alloca(llty, size=ir.Constant(intp, int(np.prod(shape))))
            strides = [size * int(np.prod(shape[i + 1 :])) for i in range(ndim)]
            return _array_value(
                context,
                builder,
                arrty,
                data,
                [ir.Constant(intp, n) for n in shape],
                [ir.Constant(intp, s) for s in strides],
            )

        return arrty(*sizes), codegen

    if ndim == 1:
        return intrinsic(lambda typingctx, n: typer(typingctx, n))
    return intrinsic(lambda typingctx, rows, cols: typer(typingctx, rows, cols))


def _view_array(ndim: int, offset: bool = False):
    """A Numba intrinsic ``f(a, *shape)`` (``ndim`` integer sizes): the first prod(shape) entries
    of the C-order array ``a`` (in memory order) as a C-order array of that shape (same data,
    dtype and owner, whose reference count it takes; :data:`view2`).  With ``offset``,
    ``f(a, start, *shape)``: the entries from flat index ``start`` on, as a borrowed view — no
    owner and no reference count (a slice or an owned view takes a reference, an atomic
    increment and decrement of ``a``'s count, which a plan unpacked into a dozen views paid on
    every call of a one-pose kernel); it must not outlive ``a`` (never returned or kept beyond
    the kernel's call: :data:`part`)."""

    def typer(typingctx, arr, start, sizes):
        if not (isinstance(arr, types.Array) and arr.layout == "C") or not all(
            isinstance(n, types.Integer) for n in (start, *sizes)
        ):
            raise numba.errors.TypingError(f"a view takes a C-order array and {ndim} integer sizes")
        outty = arr.copy(ndim=ndim, layout="C")

        def codegen(context, builder, sig, args):
            src_model = context.data_model_manager[sig.args[0]]
            field = src_model.get_field_position
            src, k = args[0], 1 + offset
            shape = [
                context.cast(builder, v, t, types.intp) for v, t in zip(args[k:], sig.args[k:])
            ]
            itemsize = builder.extract_value(src, field("itemsize"))
            strides = [itemsize]
            for n in shape[:0:-1]:
                strides.insert(0, builder.mul(strides[0], n))
            data = builder.extract_value(src, field("data"))
            if offset:  # borrowed
                first = context.cast(builder, args[1], sig.args[1], types.intp)
                return _array_value(
                    context, builder, outty, builder.gep(data, [first]), shape, strides
                )
            out = _array_value(
                context,
                builder,
                outty,
                data,
                shape,
                strides,
                meminfo=builder.extract_value(src, field("meminfo")),
                parent=builder.extract_value(src, field("parent")),
            )
            if context.enable_nrt:  # a view returned: it holds a reference
                context.nrt.incref(builder, outty, out)
            return out

        return outty(arr, *((start,) if offset else ()), *sizes), codegen

    if offset:
        if ndim == 1:
            return intrinsic(lambda typingctx, arr, start, n: typer(typingctx, arr, start, (n,)))
        return intrinsic(
            lambda typingctx, arr, start, rows, cols: typer(typingctx, arr, start, (rows, cols))
        )
    if ndim == 2:
        return intrinsic(
            lambda typingctx, arr, rows, cols: typer(typingctx, arr, types.intp, (rows, cols))
        )
    return intrinsic(
        lambda typingctx, arr, d0, d1, d2: typer(typingctx, arr, types.intp, (d0, d1, d2))
    )


#: ``view2(a, rows, cols)`` / ``view3(a, d0, d1, d2)``: ``a.ravel()[:k].reshape(shape)`` of a
#: C-order array ``a`` (:func:`_view_array`) without reshape's run-time layout search (a call
#: of Numba's C helper: the dozen a one-pose IK kernel made on every call took 0.25 µs of its
#: 1.6).  ``part(a, start, n)`` / ``part2(a, start, rows, cols)``: the same from flat index
#: ``start`` (``a.ravel()[start:start + k]``), borrowed (no reference count: it must not outlive
#: ``a``).  Unchecked: the sizes must fit in ``a``.
view2 = _view_array(2)
view3 = _view_array(3)
part = _view_array(1, offset=True)
part2 = _view_array(2, offset=True)


@intrinsic
def borrow(typingctx, arr):
    """``borrow(a)``: the C-order array ``a`` itself (same data, shape and type), borrowed — no
    owner and no reference count.  An array argument of a kernel called from Python holds a
    reference (Numba's runtime), which each kernel it is passed on to may take and give back
    (an atomic increment and decrement per call); its borrowed view, passed on instead, costs
    none of them.  It must not outlive ``a`` (never returned or kept beyond the call)."""
    if not (isinstance(arr, types.Array) and arr.layout == "C"):
        raise numba.errors.TypingError("borrow takes a C-order array")

    def codegen(context, builder, sig, args):
        field = context.data_model_manager[sig.args[0]].get_field_position
        src, ndim = args[0], sig.args[0].ndim
        shape = [builder.extract_value(src, [field("shape"), i]) for i in range(ndim)]
        strides = [builder.extract_value(src, [field("strides"), i]) for i in range(ndim)]
        data = builder.extract_value(src, field("data"))
        return _array_value(context, builder, sig.return_type, data, shape, strides)

    return arr(arr), codegen


#: ``local(n)`` / ``local2(rows, cols)``: float64 scratch arrays of literal sizes in the stack
#: frame of the kernel that makes them (:func:`_local_array`); ``local_flags(n)`` booleans,
#: ``local_ints2(rows, cols)`` int64.  Such an array must not outlive its kernel: it is never
#: returned (copy out its values).
local = _local_array(types.float64, 1)
local2 = _local_array(types.float64, 2)
local_flags = _local_array(types.boolean, 1)
local_ints2 = _local_array(types.int64, 2)

#: what the reference runs for each of them (by ``id``)
PY_FORMS = {
    id(local): lambda n: np.empty(n),
    id(local2): lambda r, c: np.empty((r, c)),
    id(local_flags): lambda n: np.empty(n, np.bool_),
    id(local_ints2): lambda r, c: np.empty((r, c), np.int64),
    id(view2): lambda a, r, c: a.reshape(-1)[: r * c].reshape(r, c),
    id(view3): lambda a, x, y, z: a.reshape(-1)[: x * y * z].reshape(x, y, z),
    id(part): lambda a, s, n: a.reshape(-1)[s : s + n],
    id(part2): lambda a, s, r, c: a.reshape(-1)[s : s + r * c].reshape(r, c),
    id(borrow): lambda a: a,
}
