"""The panels' way to the GPU: plain data queued in ``state.gpu`` (shadelab.lab.gpu_queue) and
served by the viewer's GL side (shadelab.ui.gpu_side) once per frame."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.lab.gpu_queue import GpuQueue, Texture
from shadelab.scene import load_preset

# ---------------------------------------------------------------- the queue (no GL)


def test_queue_keeps_the_newest_upload_and_request_per_key():
    q = GpuQueue()
    q.upload("a", np.zeros((2, 3, 3), np.uint8))
    q.upload("a", np.ones((4, 5, 3), np.uint8))
    assert list(q.uploads) == ["a"] and q.uploads["a"].shape == (4, 5, 3)
    q.results["r"] = "old"
    q.request("r", "raster", size=(8, 8))
    q.request("r", "raster", size=(16, 8))
    assert q.pending("r") and q.requests["r"].args == {"size": (16, 8)}
    assert q.take("r") is None          # the old result went with the new request
    assert q.texture("a") is None       # nothing is on the GPU until the GL side flushed


@pytest.mark.parametrize("image", [np.zeros((4, 4), np.uint8), np.zeros((4, 4, 2), np.uint8),
                                   np.zeros((4, 4, 3), np.float32)])
def test_upload_refuses_what_is_not_an_rgb8_image(image):
    with pytest.raises(ValueError, match="expected \\(H, W, 3\\) or \\(H, W, 4\\) uint8"):
        GpuQueue().upload("bad", image)


# ---------------------------------------------------------------- the GL side


@pytest.fixture
def side(gl_ctx):
    from shadelab.ui.gpu_side import GpuSide
    from shadelab.ui.viewport import Viewport

    vp = Viewport(gl_ctx)
    gpu = GpuSide(vp)
    yield gpu
    gpu.release()
    vp.release()


@pytest.mark.gl
def test_flush_uploads_and_registers_the_texture_by_id_and_size(side, np_rng):
    q = GpuQueue()
    image = np_rng.integers(0, 256, (5, 7, 3), dtype=np.uint8)
    q.upload("img", image)
    side.flush(q)
    assert q.attached and not q.uploads
    tex = q.texture("img")
    assert isinstance(tex, Texture) and isinstance(tex.id, int) and tex.size == (7, 5)
    gl_tex = side.viewport.images["img"]
    assert gl_tex.glo == tex.id
    data = np.frombuffer(gl_tex.read(), np.uint8).reshape(5, 7, 4)
    np.testing.assert_array_equal(data[..., :3], image)   # row 0 first, as uploaded


@pytest.mark.gl
def test_raster_request_equals_the_viewport_drawing_it(side):
    from shadelab.ui.viewport import Viewport

    scene = load_preset("cornell")
    q = GpuQueue()
    q.request("job_raster", "raster", scene=scene, size=(40, 30), shading="phong",
              specular="phong")
    side.flush(q)
    got = q.take("job_raster")
    assert got is not None and got.shape == (30, 40, 3) and not q.pending("job_raster")
    assert q.take("job_raster") is None    # taken once
    vp = Viewport(side.viewport.ctx)
    try:
        vp.draw_scene("x", scene, (40, 30), "phong", "phong")
        np.testing.assert_array_equal(got, vp.read_linear("x"))
    finally:
        vp.release()
    assert float(got.max()) > 0.0


@pytest.mark.gl
def test_hemicube_requests_give_the_rows_and_images_of_the_hemicube(side, gl_ctx):
    from shadelab.radiosity.patches import uniform_patches
    from shadelab.raster.hemicube import Hemicube

    scene = load_preset("cornell")
    patches = uniform_patches(scene, 40)
    args = {"key": "k", "patches": patches, "resolution": 32}
    q = GpuQueue()
    q.request("hemicube_rows", "hemicube_rows", start=3, **args)
    q.request("hemicube_images", "hemicube_images", patch=5, **args)
    side.flush(q)
    rows, images = q.take("hemicube_rows"), q.take("hemicube_images")
    cube = Hemicube(patches, 32, ctx=gl_ctx)
    try:
        want = np.arange(3, min(len(patches), 3 + cube.batch))
        np.testing.assert_array_equal(rows["rows"], want)
        np.testing.assert_allclose(rows["values"], cube.rows(want), atol=1e-12)
        assert rows["batch"] == cube.batch and images["res"] == cube.res
        np.testing.assert_array_equal(images["images"]["top"], cube.item_images(5)["top"])
    finally:
        cube.release()
    first = side._hemicube[1]
    q.request("hemicube_rows", "hemicube_rows", start=0, **args)
    side.flush(q)
    assert side._hemicube[1] is first       # the same geometry key: the same hemicube


@pytest.mark.gl
def test_a_failing_request_is_one_line_in_errors_and_the_rest_still_runs(side):
    q = GpuQueue()
    q.request("bad", "no-such-work")
    q.request("raster", "raster", scene=load_preset("cornell"), size=(8, 8),
              shading="flat", specular="phong")
    side.flush(q)
    assert q.errors["bad"] == "no-such-work: no GPU handler for 'no-such-work'"
    assert q.take("bad") is None and q.take("raster") is not None
