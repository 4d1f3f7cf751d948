"""ctypes declarations of libdhcal_py, the package's C boundary (python/src/dhcal_py.h).

The library keeps the analysis' large workspaces in static storage and is not thread-safe:
it is loaded with ``ctypes.PyDLL``, whose calls keep the interpreter lock, so two Python
threads can never be inside it at once.
"""
from __future__ import annotations

import ctypes
from pathlib import Path
from typing import Optional

ERR_CAP = 1024

OK, FAILED, BAD_INPUT = 0, 1, 2


class Rows(ctypes.Structure):
    """dhcal_py_rows: row-major float64 arrays; absent columns are NULL."""

    _fields_ = [
        ("n_rows", ctypes.c_size_t),
        ("q_deg", ctypes.POINTER(ctypes.c_double)),
        ("xyz_mm", ctypes.POINTER(ctypes.c_double)),
        ("dir", ctypes.POINTER(ctypes.c_double)),
        ("temp_c", ctypes.POINTER(ctypes.c_double)),
        ("t_s", ctypes.POINTER(ctypes.c_double)),
        ("wires_mm", ctypes.POINTER(ctypes.c_double)),
        ("plane", ctypes.POINTER(ctypes.c_double)),
        ("point", ctypes.POINTER(ctypes.c_double)),
        ("pair", ctypes.POINTER(ctypes.c_double)),
        ("distance_mm", ctypes.POINTER(ctypes.c_double)),
    ]


def _find_library() -> Path:
    here = Path(__file__).resolve().parent
    for name in ("libdhcal_py.so", "libdhcal_py.dylib", "dhcal_py.dll"):
        if (here / name).exists():
            return here / name
    raise ImportError(f"dhcal: the native library libdhcal_py is missing from {here}; "
                      "reinstall the package (pip install ./python)")


def _load() -> ctypes.PyDLL:
    lib = ctypes.PyDLL(str(_find_library()))
    c_char_p, c_int, c_size_t, c_void_p = (ctypes.c_char_p, ctypes.c_int, ctypes.c_size_t,
                                           ctypes.c_void_p)
    pd = ctypes.POINTER(ctypes.c_double)
    # Text the library allocates comes back as a void pointer: c_char_p would copy it and
    # lose the pointer that dhcal_py_free needs.
    lib.dhcal_py_version.restype = c_char_p
    lib.dhcal_py_version.argtypes = []
    lib.dhcal_py_model_load.restype = c_void_p
    lib.dhcal_py_model_load.argtypes = [c_char_p, ctypes.POINTER(c_int), c_char_p, c_size_t]
    lib.dhcal_py_model_free.restype = None
    lib.dhcal_py_model_free.argtypes = [c_void_p]
    lib.dhcal_py_model_save.restype = c_int
    lib.dhcal_py_model_save.argtypes = [c_void_p, c_char_p, c_char_p, c_size_t]
    lib.dhcal_py_model_info.restype = c_void_p
    lib.dhcal_py_model_info.argtypes = [c_void_p]
    lib.dhcal_py_rows_load.restype = c_int
    lib.dhcal_py_rows_load.argtypes = [c_char_p, c_void_p, ctypes.POINTER(c_void_p),
                                       ctypes.POINTER(c_size_t), ctypes.POINTER(c_int),
                                       c_char_p, c_size_t]
    lib.dhcal_py_rows_copy.restype = None
    lib.dhcal_py_rows_copy.argtypes = [c_void_p, pd, pd, pd, pd, pd, pd, pd, pd, pd, pd]
    lib.dhcal_py_rows_free.restype = None
    lib.dhcal_py_rows_free.argtypes = [c_void_p]
    lib.dhcal_py_run.restype = c_int
    lib.dhcal_py_run.argtypes = [c_char_p, c_void_p, ctypes.POINTER(Rows), ctypes.POINTER(Rows),
                                 c_char_p, c_char_p, c_char_p, c_int,
                                 ctypes.POINTER(c_void_p), ctypes.POINTER(c_void_p),
                                 c_char_p, c_size_t]
    lib.dhcal_py_units_check.restype = c_int
    lib.dhcal_py_units_check.argtypes = [c_void_p, ctypes.POINTER(Rows), ctypes.POINTER(Rows),
                                         c_char_p, c_char_p, c_size_t]
    lib.dhcal_py_free.restype = None
    lib.dhcal_py_free.argtypes = [c_void_p]
    return lib


LIB = _load()


def take_text(ptr: Optional[int]) -> Optional[str]:
    """The library's text at ptr as a str; the library's copy is freed."""
    if not ptr:
        return None
    try:
        return ctypes.string_at(ptr).decode("utf-8")
    finally:
        LIB.dhcal_py_free(ptr)


def err_buffer() -> ctypes.Array:
    return ctypes.create_string_buffer(ERR_CAP)


def encode(text: Optional[str]) -> Optional[bytes]:
    return None if text is None else text.encode("utf-8")
