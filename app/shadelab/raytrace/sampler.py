"""Owen-scrambled Sobol' samples for the path tracer, in numba (issue 19.3).

Every 2-D decision of a path (pixel jitter; per vertex the emitter point, the BSDF
direction, and the lobe choice with Russian roulette) draws the first two dimensions of
Sobol' (a (0,2)-sequence: van der Corput and the x + 1 matrix) at the pixel's sample index,
with Burley's "Practical Hash-based Owen Scrambling" (JCGT 2020):

- the index is shuffled by a nested uniform scramble of its bits, seeded per pixel and per
  pair of dimensions, so the pairs of one path are decorrelated while each power-of-two
  prefix of a pixel's samples keeps its stratification (the shuffle permutes the index's
  low bits, the ones a prefix's leading output digits depend on);
- each coordinate is Owen-scrambled (the Laine-Karras hash as pbrt-v4's
  ``FastOwenScrambler``), seeded per pixel, pair and coordinate.

Each pixel's samples 0 .. 2^m - 1 of any pair are a (0, m, 2)-net: every pixel, every
pair, any prefix of a power-of-two count. Seeds, pixels and pairs are hashed together, so
another ``seed`` gives an independent randomization (the images are unbiased and their
variance across seeds measures the estimator's error).

Dimensions: pair 0 jitters the pixel; vertex b uses pairs 1 + 3b (emitter point), 2 + 3b
(BSDF direction, or the Fresnel choice), 3 + 3b (lobe choice, roulette). The emitter's
triangle is picked with the first coordinate and that coordinate re-scaled inside the
triangle's stretch of the area CDF becomes the first barycentric variable, so the 2-D
stratification covers the whole emitting area, not one triangle at a time.
"""

from __future__ import annotations

import numba as nb
import numpy as np

SAMPLERS = ("sobol", "independent")

_MASK = 0xFFFFFFFF
_TO_UNIT = 1.0 / 4294967296.0   # 2^-32: a 32-bit integer to [0, 1)


@nb.njit(cache=True, inline="always")
def _reverse_bits(x):
    x = ((x >> 1) & 0x55555555) | ((x & 0x55555555) << 1)
    x = ((x >> 2) & 0x33333333) | ((x & 0x33333333) << 2)
    x = ((x >> 4) & 0x0F0F0F0F) | ((x & 0x0F0F0F0F) << 4)
    x = ((x >> 8) & 0x00FF00FF) | ((x & 0x00FF00FF) << 8)
    return ((x >> 16) | (x << 16)) & _MASK


@nb.njit(cache=True, inline="always")
def _hash(x):
    """A 32-bit integer hash (Wellons' lowbias32)."""
    x &= _MASK
    x ^= x >> 16
    x = (x * 0x7FEB352D) & _MASK
    x ^= x >> 15
    x = (x * 0x846CA68B) & _MASK
    x ^= x >> 16
    return x


@nb.njit(cache=True, inline="always")
def _laine_karras(v, seed):
    """The Laine-Karras hash of the bit-reversed fraction v (a nested uniform scramble of
    the fraction itself), seeded."""
    v ^= (v * 0x3D20ADEA) & _MASK
    v = (v + seed) & _MASK
    v = (v * ((seed >> 16) | 1)) & _MASK
    v ^= (v * 0x05526C56) & _MASK
    v ^= (v * 0x53A22864) & _MASK
    return v


@nb.njit(cache=True, inline="always")
def _owen(v, seed):
    """Nested uniform (Owen) scramble of the 32-bit fraction v, seeded (pbrt-v4's
    FastOwenScrambler: Laine-Karras on the reversed bits)."""
    return _reverse_bits(_laine_karras(_reverse_bits(v), seed))


def _dimension1_bytes() -> np.ndarray:
    """Sobol' dimension 1 (direction numbers v_1 = 2^31, v_k+1 = v_k ^ (v_k >> 1)) as four
    tables of 256: the XOR of the columns of each byte of the index."""
    v = [0x80000000]
    for _ in range(31):
        v.append(v[-1] ^ (v[-1] >> 1))
    table = np.zeros((4, 256), np.int64)
    for byte in range(4):
        for value in range(256):
            y = 0
            for bit in range(8):
                if value >> bit & 1:
                    y ^= v[8 * byte + bit]
            table[byte, value] = y
    return table


_DIM1 = _dimension1_bytes()


@nb.njit(cache=True, inline="always")
def _sobol2(index):
    """Sobol' dimensions 0 and 1 of ``index`` as 32-bit fractions."""
    return _reverse_bits(index), (_DIM1[0, index & 255] ^ _DIM1[1, (index >> 8) & 255]
                                  ^ _DIM1[2, (index >> 16) & 255] ^ _DIM1[3, index >> 24])


@nb.njit(cache=True, inline="always")
def _pixel_seed(seed, pixel):
    return _hash(_hash(seed ^ 0x5BD1E995) ^ (pixel & _MASK) ^ _hash(pixel >> 32))


@nb.njit(cache=True, inline="always")
def sample_2d(pixel_seed, pair, index):
    """The (u, v) in [0, 1)^2 of sample ``index`` of one pixel's pair of dimensions."""
    h = _hash(pixel_seed ^ _hash(pair + 0x68E31DA4))
    j = _owen(index & _MASK, h)
    # dimension 0 is j bit-reversed, so its scramble _owen(reverse(j)) skips two reversals
    x = _reverse_bits(_laine_karras(j, _hash(h ^ 0x1B873593)))
    y = _owen(_sobol2(j)[1], _hash(h ^ 0xCC9E2D51))
    return x * _TO_UNIT, y * _TO_UNIT


@nb.njit(cache=True, parallel=True)
def sobol_pairs(seed, pixels, pair, indices):
    """(n, 2): pair ``pair`` of sample ``indices[i]`` of pixel ``pixels[i]``."""
    n = len(pixels)
    out = np.empty((n, 2))
    for i in nb.prange(n):
        out[i, 0], out[i, 1] = sample_2d(_pixel_seed(seed, pixels[i]), pair, indices[i])
    return out


@nb.njit(cache=True, inline="always")
def vertex_draws(ps, index, bounce, em_cdf):
    """The 7 uniforms of path vertex ``bounce`` of sample ``index`` of the pixel whose seed is
    ``ps`` (:func:`_pixel_seed`): emitter, 2 barycentrics, lobe, 2 direction, roulette, from
    pairs 1 + 3b, 2 + 3b and 3 + 3b."""
    base = 1 + 3 * bounce
    n_em = len(em_cdf)
    u, v = sample_2d(ps, base, index)
    # the first barycentric variable: u re-scaled inside its triangle's CDF stretch
    w = u
    if n_em > 0:
        k = min(np.searchsorted(em_cdf, u, side="right"), n_em - 1)
        lo = em_cdf[k - 1] if k > 0 else 0.0
        width = em_cdf[k] - lo
        w = min(max((u - lo) / width, 0.0), 1.0 - 1e-16) if width > 0.0 else 0.5
    d1, d2 = sample_2d(ps, base + 1, index)
    lobe, roulette = sample_2d(ps, base + 2, index)
    return u, w, v, lobe, d1, d2, roulette


@nb.njit(cache=True, parallel=True)
def vertex_uniforms(seed, pixels, indices, bounce, em_cdf):
    """The 7 uniforms per path of :func:`shadelab.raytrace.vertex.path_vertex` (emitter,
    2 barycentrics, lobe, 2 direction, roulette; :func:`vertex_draws`) of sample
    ``indices[i]`` of pixel ``pixels[i]``."""
    n = len(pixels)
    out = np.empty((n, 7))
    for i in nb.prange(n):
        (out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4], out[i, 5],
         out[i, 6]) = vertex_draws(_pixel_seed(seed, pixels[i]), indices[i], bounce, em_cdf)
    return out


class SobolSampler:
    """The Sobol' draws of a batch of paths: path i is sample ``indices[i]`` of the image's
    pixel ``pixels[i]`` (row-major ids)."""

    def __init__(self, seed: int, pixels: np.ndarray, indices: np.ndarray):
        self.seed = int(seed) & _MASK
        self.pixels = np.ascontiguousarray(pixels, dtype=np.int64)
        self.indices = np.ascontiguousarray(np.broadcast_to(indices, self.pixels.shape),
                                            dtype=np.int64)

    def jitter(self) -> np.ndarray:
        """(n, 2) pixel offsets in [0, 1) of the paths."""
        return sobol_pairs(self.seed, self.pixels, 0, self.indices)

    def vertex(self, paths: np.ndarray, bounce: int, em_cdf: np.ndarray) -> np.ndarray:
        """(len(paths), 7) uniforms of the path vertex ``bounce`` of those paths."""
        return vertex_uniforms(self.seed, self.pixels[paths], self.indices[paths], bounce,
                               np.ascontiguousarray(em_cdf, dtype=np.float64))
