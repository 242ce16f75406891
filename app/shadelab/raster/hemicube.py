"""GPU hemicube form factors (Cohen & Greenberg 1985) on the shared headless EGL context.

For each patch a camera sits at its centre and renders every patch, id + 1 into an integer
item buffer (``u4`` texture, ``flat out uint``), on the five faces of a hemicube: the top face
(res x res) along the normal and the upper halves of four side faces (res x res/2, asymmetric
frusta). Each pixel carries a delta form factor; F_ij sums those of the pixels showing j.
Several patches share one atlas so that one read-back serves a batch.

The GL-free form-factor engine gets this class passed in as its backend
(``FormFactors(..., hemicube=Hemicube)``): the radiosity package itself imports no GL.
"""

from __future__ import annotations

import moderngl
import numpy as np

from shadelab.errors import ShadeLabError
from shadelab.gl.context import headless_context
from shadelab.gl.programs import load_program
from shadelab.gl.target import bind_anchor
from shadelab.radiosity.patches import PatchSet
from shadelab.radiosity.sampling import hemicube_delta_factors, receiver_samples

ATLAS_MAX = 4096  # pixels: the atlas is res*5 wide and res*batch high


def _frustum(left: float, right: float, bottom: float, top: float, near: float, far: float):
    """OpenGL ``clip_from_view`` (column-vector convention)."""
    return np.array([[2 * near / (right - left), 0, (right + left) / (right - left), 0],
                     [0, 2 * near / (top - bottom), (top + bottom) / (top - bottom), 0],
                     [0, 0, -(far + near) / (far - near), -2 * far * near / (far - near)],
                     [0, 0, -1, 0]])


def _view(eye: np.ndarray, forward: np.ndarray, up: np.ndarray) -> np.ndarray:
    """``view_from_world`` looking along ``forward`` (column-vector convention)."""
    right = np.cross(forward, up)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = right, up, -forward
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def rebind(ctx: moderngl.Context, previous) -> None:
    """Bind ``previous`` again (or the context's anchor framebuffer if it is gone), so that a
    later ``ctx.framebuffer(...)`` does not try to restore a released one."""
    if previous is not None and type(previous.mglo).__name__ != "InvalidObject":
        previous.use()
    else:
        bind_anchor(ctx)


def tangent_frame(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors t, b with (t, b, n) right-handed and orthonormal."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t = np.cross(helper, n)
    t /= np.linalg.norm(t)
    return t, np.cross(n, t)


def gl_size_limit(ctx: moderngl.Context) -> int:
    """The widest texture, renderbuffer and viewport this GL draws (pixels)."""
    return min(int(ctx.info.get("GL_MAX_TEXTURE_SIZE", 4096)),
               int(ctx.info.get("GL_MAX_RENDERBUFFER_SIZE", 4096)),
               int(ctx.info.get("GL_MAX_VIEWPORT_DIMS", (4096, 4096))[0]))


def check_resolution(ctx: moderngl.Context, res: int) -> None:
    """One line instead of moderngl's 'framebuffer is not complete' past the GL's limit (the
    atlas lays a hemicube's five faces side by side)."""
    limit = gl_size_limit(ctx)
    if 5 * res > limit:
        raise ShadeLabError(f"radiosity.hemicube_resolution {res}: the hemicube's five faces "
                            f"({5 * res} px wide) exceed this GL's limit of {limit} px; use at "
                            f"most {limit // 5 // 2 * 2}, or raycast form factors")


class Hemicube:
    """Item-buffer hemicubes of a patch set; ``rows(indices)`` gives form-factor rows."""

    def __init__(self, patches: PatchSet, resolution: int = 128, samples: int = 1,
                 ctx: moderngl.Context | None = None):
        self.patches = patches
        # Hemicubes per patch: 1 at the centre (Cohen & Greenberg), or an order x order
        # Gauss-Legendre grid when the patch is large next to its distance to others
        if samples <= 1:
            self.eyes, self.eye_w = patches.centers[:, None, :], np.ones((len(patches), 1))
        else:
            order = int(round(np.sqrt(samples)))
            self.eyes, self.eye_w = receiver_samples(patches.polygons, order)
        self.res = max(2, int(resolution) // 2 * 2)
        self.ctx = ctx or headless_context()
        check_resolution(self.ctx, self.res)
        self.program = load_program(self.ctx, "hemicube")
        self.batch = max(1, min(32, ATLAS_MAX // self.res))
        n = len(patches)
        tri = np.concatenate([patches.polygons[:, [0, 1, 2]], patches.polygons[:, [0, 2, 3]]], 1)
        ids = np.repeat(np.arange(1, n + 1, dtype=np.uint32), 6)
        data = np.zeros(n * 6, dtype=[("p", "f4", 3), ("id", "u4")])
        data["p"] = tri.reshape(-1, 3)
        data["id"] = ids
        self.vbo = self.ctx.buffer(data.tobytes())
        self.vao = self.ctx.vertex_array(self.program, [(self.vbo, "3f 1u", "in_position",
                                                         "in_id")])
        size = (5 * self.res, self.batch * self.res)
        self.color = self.ctx.texture(size, 1, dtype="u4")
        self.depth = self.ctx.depth_renderbuffer(size)
        self.fbo = self.ctx.framebuffer([self.color], self.depth)
        span = np.ptp(patches.polygons.reshape(-1, 3), axis=0)
        diag = float(max(np.linalg.norm(span), 1e-12))
        self.near, self.far = 1e-4 * diag, 4.0 * diag
        self.weights = self._weight_atlas()
        self._batch_weights = np.tile(self.weights.ravel(), self.batch)  # a batch's strips

    def _weight_atlas(self) -> np.ndarray:
        """Delta form factors laid out like one patch's strip of the atlas (res, 5 res)."""
        res = self.res
        top, side = hemicube_delta_factors(res)
        strip = np.zeros((res, 5 * res))
        strip[:, :res] = top
        for f in range(1, 5):
            strip[res - res // 2:, f * res:(f + 1) * res] = side
        return strip

    def _faces(self, i: int, k: int = 0):
        """(viewport, clip_from_world) of the five faces of patch i's hemicube number k."""
        n = self.patches.normals[i]
        t, b = tangent_frame(n)
        eye = self.eyes[i, k] + n * self.near * 2.0
        nr, fr, res = self.near, self.far, self.res
        top = _frustum(-nr, nr, -nr, nr, nr, fr) @ _view(eye, n, b)
        yield (0, 0, res, res), top
        half = _frustum(-nr, nr, 0.0, nr, nr, fr)
        for f, forward in enumerate((t, b, -t, -b), start=1):
            yield (f * res, 0, res, res // 2), half @ _view(eye, forward, n)

    def _clip_batch(self, indices: np.ndarray, sample: int) -> np.ndarray:
        """(len, 5, 4, 4) float32 ``clip_from_world.T`` of the faces of :meth:`_faces`, for
        all the patches at once (numpy over the batch instead of per face)."""
        n = self.patches.normals[indices]
        helper = np.where((np.abs(n[:, 0]) < 0.9)[:, None], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
        t = np.cross(helper, n)
        t /= np.linalg.norm(t, axis=1, keepdims=True)
        b = np.cross(n, t)
        eye = self.eyes[indices, sample] + n * self.near * 2.0
        nr, fr = self.near, self.far
        # (forward, up) of the five faces: top along n (up b), sides along t, b, -t, -b (up n)
        forward = np.stack([n, t, b, -t, -b], axis=1)
        up = np.stack([b, n, n, n, n], axis=1)
        right = np.cross(forward, up)
        view = np.zeros((len(indices), 5, 4, 4))
        view[..., 0, :3], view[..., 1, :3], view[..., 2, :3] = right, up, -forward
        view[..., :3, 3] = -np.einsum("fij,fj->fi", view[..., :3, :3].reshape(-1, 3, 3),
                                      np.repeat(eye, 5, axis=0)).reshape(len(indices), 5, 3)
        view[..., 3, 3] = 1.0
        top, half = _frustum(-nr, nr, -nr, nr, nr, fr), _frustum(-nr, nr, 0.0, nr, nr, fr)
        proj = np.stack([top, half, half, half, half])
        clip = proj[None] @ view
        return np.ascontiguousarray(np.swapaxes(clip, -1, -2), dtype=np.float32)

    def item_atlas(self, indices: np.ndarray, sample: int = 0) -> np.ndarray:
        """Item ids (len, res, 5 res) uint32 (id + 1, 0 = nothing) for up to ``batch`` patches
        (their hemicube number ``sample``).

        Row 0 of each strip is the top of the image: for side faces, nearest the normal.
        """
        ctx, res = self.ctx, self.res
        previous = ctx.fbo  # bound again afterwards: nobody is left on a released fbo
        self.fbo.use()
        self.fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        ctx.enable_only(moderngl.DEPTH_TEST)
        clips = self._clip_batch(np.asarray(indices, np.int64), sample)
        uniform = self.program["u_clip_from_world"]
        boxes = [(0, 0, res, res)] + [(f * res, 0, res, res // 2) for f in range(1, 5)]
        for slot in range(len(indices)):
            base_y = (self.batch - 1 - slot) * res  # slot 0 at the top after the row flip
            for face, (x, y, w, h) in enumerate(boxes):
                self.fbo.viewport = (x, base_y + y, w, h)
                uniform.write(clips[slot, face])
                self.vao.render(moderngl.TRIANGLES)
        self.fbo.viewport = (0, 0, *self.fbo.size)
        # One read-back per batch, of the slots drawn only (they are the atlas's top rows)
        used = len(indices) * res
        raw = np.frombuffer(self.fbo.read(viewport=(0, self.batch * res - used, 5 * res, used),
                                          components=1, dtype="u4", alignment=1),
                            dtype=np.uint32)
        rebind(ctx, previous)
        atlas = raw.reshape(used, 5 * res)[::-1]
        return atlas.reshape(len(indices), res, 5 * res)

    def rows(self, indices: np.ndarray) -> np.ndarray:
        """Form-factor rows (len(indices), N): delta form factors summed per item."""
        n = len(self.patches)
        out = np.zeros((len(indices), n))
        for start in range(0, len(indices), self.batch):
            part = indices[start:start + self.batch]
            for sample in range(self.eyes.shape[1]):
                atlas = self.item_atlas(part, sample)
                # One bincount for the batch: patch k's items offset by k (N + 1)
                keys = atlas.reshape(len(part), -1).astype(np.int64)
                keys += (np.arange(len(part)) * (n + 1))[:, None]
                weights = self._batch_weights[:keys.size]
                sums = np.bincount(keys.ravel(), weights=weights,
                                   minlength=len(part) * (n + 1)).reshape(len(part), n + 1)
                out[start:start + len(part)] += self.eye_w[part, sample][:, None] * sums[:, 1:]
            out[np.arange(start, start + len(part)), part] = 0.0
        return out

    def item_images(self, i: int) -> dict:
        """The hemicube of patch i for teaching: item images (-1 = nothing) and delta factors.

        Returns ``top`` (res, res) int, ``sides`` list of 4 (res/2, res) int, ``top_dF``,
        ``side_dF`` and the form-factor row.
        """
        atlas = self.item_atlas(np.array([i]))[0].astype(np.int64) - 1
        res = self.res
        top_df, side_df = hemicube_delta_factors(res)
        sides = [atlas[res - res // 2:, f * res:(f + 1) * res] for f in range(1, 5)]
        n = len(self.patches)
        seen = atlas >= 0      # the row from this very atlas (one render, not two)
        row = np.bincount(atlas[seen], weights=self.weights[seen], minlength=n)[:n]
        if self.eyes.shape[1] > 1:   # several hemicubes per patch: the row is their mean
            row = self.rows(np.array([i]))[0]
        row[i] = 0.0
        return {"top": atlas[:, :res], "sides": sides, "top_dF": top_df, "side_dF": side_df,
                "row": row}

    def release(self) -> None:
        for obj in (self.vao, self.vbo, self.fbo, self.color, self.depth):
            obj.release()


def item_images(patches: PatchSet, i: int, resolution: int = 64) -> dict:
    """Hemicube item images of patch ``i`` from its centre (see :meth:`Hemicube.item_images`)."""
    cube = Hemicube(patches, resolution)
    try:
        return cube.item_images(i)
    finally:
        cube.release()
