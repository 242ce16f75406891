"""Embree called from numba kernels, one ray at a time (issue 19.3).

``embreex`` traces a whole numpy batch per call, so a path tracer built on it is a wavefront:
each bounce goes back to Python to cast its rays. Here the Embree 4 library that embreex
ships (``embreex.libs/libembree4*.so``) is opened with ``ctypes``, a scene of the same
triangles is built the way embreex builds one (flat triangles, robust flag), and numba code
calls ``rtcIntersect1`` / ``rtcOccluded1`` through their addresses (:func:`intersect1`,
:func:`occluded1`: the addresses are arguments, not globals, so the kernels stay in numba's
cache). Whole paths then run in one parallel numba loop (:mod:`shadelab.raytrace.fused`).

Where the library cannot be found or opened, :func:`embree_scene` returns None and the path
tracer stays on its wavefront.
"""

from __future__ import annotations

import ctypes
import glob
import os

import numba as nb
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

RTC_GEOMETRY_TYPE_TRIANGLE = 0
RTC_BUFFER_TYPE_INDEX = 0
RTC_BUFFER_TYPE_VERTEX = 1
RTC_FORMAT_UINT3 = 0x5003
RTC_FORMAT_FLOAT3 = 0x9003
RTC_SCENE_FLAG_ROBUST = 1 << 2   # as embreex.rtcore_scene.EmbreeScene(robust=True), its default
INVALID_ID = 0xFFFFFFFF

# One RTCRayHit (Embree 4: RTCRay 48 bytes, RTCHit 32 or 48, both 16-aligned) as float32
# words in a buffer of RAY_WORDS; the word offsets of the fields the kernels use
RAY_WORDS = 32
ORG, TNEAR, DIR, TIME, TFAR, MASK, ID, FLAGS = 0, 3, 4, 7, 8, 9, 10, 11
HIT_U, HIT_V, PRIM_ID, GEOM_ID, INST_ID = 15, 16, 17, 18, 19

_LIB: ctypes.CDLL | None = None
_LIB_TRIED = False


def _library() -> ctypes.CDLL | None:
    """embreex's Embree 4, opened once (None where embreex or its library is missing)."""
    global _LIB, _LIB_TRIED
    if _LIB_TRIED:
        return _LIB
    _LIB_TRIED = True
    if os.environ.get("SHADELAB_EMBREE_DIRECT", "1") == "0":
        return None
    try:
        import embreex
        import embreex.rtcore_scene  # noqa: F401  (loads the library the way embreex does)
    except ImportError:
        return None
    root = os.path.dirname(os.path.dirname(os.path.abspath(embreex.__file__)))
    found = sorted(glob.glob(os.path.join(root, "embreex.libs", "libembree4*.so*"))
                   + glob.glob(os.path.join(os.path.dirname(embreex.__file__),
                                            "libembree4*.so*")))
    for path in found:
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        p = ctypes.c_void_p
        lib.rtcNewDevice.restype, lib.rtcNewDevice.argtypes = p, [ctypes.c_char_p]
        lib.rtcGetDeviceError.restype, lib.rtcGetDeviceError.argtypes = ctypes.c_int, [p]
        lib.rtcNewScene.restype, lib.rtcNewScene.argtypes = p, [p]
        lib.rtcSetSceneFlags.restype, lib.rtcSetSceneFlags.argtypes = None, [p, ctypes.c_int]
        lib.rtcNewGeometry.restype, lib.rtcNewGeometry.argtypes = p, [p, ctypes.c_int]
        lib.rtcSetNewGeometryBuffer.restype = p
        lib.rtcSetNewGeometryBuffer.argtypes = [p, ctypes.c_int, ctypes.c_uint, ctypes.c_int,
                                                ctypes.c_size_t, ctypes.c_size_t]
        lib.rtcCommitGeometry.restype, lib.rtcCommitGeometry.argtypes = None, [p]
        lib.rtcAttachGeometry.restype, lib.rtcAttachGeometry.argtypes = ctypes.c_uint, [p, p]
        lib.rtcReleaseGeometry.restype, lib.rtcReleaseGeometry.argtypes = None, [p]
        lib.rtcCommitScene.restype, lib.rtcCommitScene.argtypes = None, [p]
        lib.rtcReleaseScene.restype, lib.rtcReleaseScene.argtypes = None, [p]
        lib.rtcReleaseDevice.restype, lib.rtcReleaseDevice.argtypes = None, [p]
        _LIB = lib
        break
    return _LIB


class EmbreeScene:
    """One committed Embree scene of (F, 3, 3) triangles; ``scene`` (its handle),
    ``intersect`` and ``occluded`` (the addresses of rtcIntersect1 / rtcOccluded1) are the
    integers a kernel passes to :func:`intersect1` / :func:`occluded1`. Triangle i is
    primID i, as in :class:`shadelab.raytrace.accel.EmbreeAccel`."""

    def __init__(self, lib: ctypes.CDLL, triangles: np.ndarray):
        self._lib = lib
        self.device = lib.rtcNewDevice(None)
        if not self.device:
            raise OSError("rtcNewDevice failed")
        self.scene = lib.rtcNewScene(self.device)
        lib.rtcSetSceneFlags(self.scene, RTC_SCENE_FLAG_ROBUST)
        tris = np.ascontiguousarray(triangles, dtype=np.float32).reshape(-1, 3, 3)
        if len(tris):
            geom = lib.rtcNewGeometry(self.device, RTC_GEOMETRY_TYPE_TRIANGLE)
            count = len(tris)
            vertices = np.zeros((3 * count, 4), np.float32)  # x, y, z and a pad, as embreex
            vertices[:, :3] = tris.reshape(-1, 3)
            vbuf = lib.rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                               RTC_FORMAT_FLOAT3, 16, 3 * count)
            ctypes.memmove(vbuf, vertices.ctypes.data, vertices.nbytes)
            index = np.arange(3 * count, dtype=np.uint32).reshape(count, 3)
            ibuf = lib.rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0,
                                               RTC_FORMAT_UINT3, 12, count)
            ctypes.memmove(ibuf, index.ctypes.data, index.nbytes)
            lib.rtcCommitGeometry(geom)
            lib.rtcAttachGeometry(self.scene, geom)
            lib.rtcReleaseGeometry(geom)
        lib.rtcCommitScene(self.scene)
        error = lib.rtcGetDeviceError(self.device)
        if error:
            raise OSError(f"Embree error {error} building the scene")
        self.intersect = ctypes.cast(lib.rtcIntersect1, ctypes.c_void_p).value
        self.occluded = ctypes.cast(lib.rtcOccluded1, ctypes.c_void_p).value
        self.count = len(tris)

    def __del__(self):
        lib = getattr(self, "_lib", None)
        if lib is not None:
            lib.rtcReleaseScene(self.scene)
            lib.rtcReleaseDevice(self.device)


def embree_scene(triangles: np.ndarray) -> EmbreeScene | None:
    """A scene of ``triangles`` for the kernels, or None where Embree cannot be opened."""
    lib = _library()
    if lib is None:
        return None
    try:
        return EmbreeScene(lib, triangles)
    except OSError:
        return None


@intrinsic
def _call3(typingctx, fn, a, b):
    """fn(a, b, NULL) for the C function at address ``fn`` taking three pointers (a, b:
    addresses as uint64)."""
    sig = types.void(types.uint64, types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        addr, pa, pb = args
        ptr = ir.IntType(8).as_pointer()
        fnty = ir.FunctionType(ir.VoidType(), [ptr, ptr, ptr])
        target = builder.inttoptr(addr, fnty.as_pointer())
        builder.call(target, [builder.inttoptr(pa, ptr), builder.inttoptr(pb, ptr),
                              ir.Constant(ptr, None)])
        return context.get_dummy_value()

    return sig, codegen


@nb.njit(cache=True)
def ray_buffer():
    """(float32 words, uint32 view, address) of one 16-byte aligned RTCRayHit."""
    raw = np.empty(RAY_WORDS + 4, np.float32)
    skip = ((16 - raw.ctypes.data % 16) % 16) // 4
    words = raw[skip:skip + RAY_WORDS]
    return words, words.view(np.uint32), np.uint64(words.ctypes.data)


@nb.njit(cache=True, inline="always")
def _set_ray(words, ints, ox, oy, oz, dx, dy, dz, tmax):
    words[ORG], words[ORG + 1], words[ORG + 2] = ox, oy, oz
    words[TNEAR] = 0.0
    words[DIR], words[DIR + 1], words[DIR + 2] = dx, dy, dz
    words[TIME] = 0.0
    words[TFAR] = tmax
    ints[MASK] = INVALID_ID
    ints[ID] = 0
    ints[FLAGS] = 0
    ints[PRIM_ID] = INVALID_ID
    ints[GEOM_ID] = INVALID_ID
    ints[INST_ID] = INVALID_ID


@nb.njit(cache=True, inline="always")
def intersect1(fn, scene, words, ints, addr, ox, oy, oz, dx, dy, dz, tmax):
    """Closest hit of one ray (float64 in, cast to float32 as the batch path does):
    (triangle or -1, t, u, v) widened to float64 (t = inf for a miss)."""
    _set_ray(words, ints, np.float32(ox), np.float32(oy), np.float32(oz), np.float32(dx),
             np.float32(dy), np.float32(dz), np.float32(tmax))
    _call3(fn, scene, addr)
    if ints[GEOM_ID] == INVALID_ID:
        return -1, np.inf, 0.0, 0.0
    return (np.int64(ints[PRIM_ID]), np.float64(words[TFAR]), np.float64(words[HIT_U]),
            np.float64(words[HIT_V]))


@nb.njit(cache=True, inline="always")
def occluded1(fn, scene, words, ints, addr, ox, oy, oz, dx, dy, dz, tmax):
    """Is anything at t < tmax along the ray (Embree 4 sets tfar to -inf when so)?"""
    _set_ray(words, ints, np.float32(ox), np.float32(oy), np.float32(oz), np.float32(dx),
             np.float32(dy), np.float32(dz), np.float32(tmax))
    _call3(fn, scene, addr)
    return words[TFAR] < 0.0
