"""The job worker process: started warm ahead of the first job, reused by it, restarted after
it dies; Progress images cross it pickled once, unchanged (issue 19, the viewport's first
full-resolution sample)."""

from __future__ import annotations

import pickle

import numpy as np

from shadelab.lab import jobs
from shadelab.lab.jobs import JobRunner, WorkerProcess, _picklable, iter_reference_raster
from shadelab.progress import Progress
from shadelab.scene.preset import load_preset

SIZE = (32, 24)


def test_a_progress_image_is_not_pickled_to_test_it_and_stays_the_same():
    image = np.arange(24 * 32 * 3, dtype=np.float32).reshape(24, 32, 3)
    step = Progress(image, 0.5, "half", {"samples": 3})
    assert _picklable(step) is step
    plain = Progress(image.copy(), 0.5, "half", {"samples": 3, "bad": lambda: 0})
    sent = _picklable(plain)   # an entry that cannot cross: replaced, the image kept as is
    assert sent.image is plain.image and sent.stats["bad"] == "<function>"
    assert sent.stats["samples"] == 3
    back = pickle.loads(pickle.dumps(sent))   # what the queue sends: the same numbers
    np.testing.assert_array_equal(back.image, plain.image)


def test_only_the_image_array_is_spared_the_test_pickling(monkeypatch):
    calls = []
    real = pickle.dumps

    def dumps(value, *args, **kwargs):
        calls.append(value)
        return real(value, *args, **kwargs)

    monkeypatch.setattr(jobs.pickle, "dumps", dumps)
    image = np.ones((1039, 915, 3), np.float32)
    _picklable(Progress(image, 0.25, "tile", {"samples": 1}))
    assert calls and not any(image is part for c in calls
                             for part in (c if isinstance(c, tuple) else (c,)))


def test_the_warm_worker_is_reused_by_the_first_job_and_its_image_comes_across():
    scene = load_preset("cornell")
    runner = JobRunner()
    before = WorkerProcess.spawns
    try:
        runner.worker.warm()          # what the viewer does after its first frames
        assert WorkerProcess.spawns == before + 1
        pid = runner.worker.process.pid
        runner.start("ref", lambda: None, call=(iter_reference_raster, scene, SIZE))
        assert runner.in_process
        runner._thread.join(120.0)
        assert not runner.running and not runner.error
        assert WorkerProcess.spawns == before + 1 and runner.worker.process.pid == pid
        last = runner.snapshot()[0]
        local = list(iter_reference_raster(scene, SIZE))[-1].image
        np.testing.assert_array_equal(last.image, local)   # one pickling, the same numbers
    finally:
        runner.shutdown()
    assert runner.worker.process is None


def test_a_worker_that_dies_is_restarted_by_the_next_job():
    scene = load_preset("cornell")
    runner = JobRunner()
    before = WorkerProcess.spawns
    try:
        runner.worker.ensure()
        first = runner.worker.process
        first.kill()
        first.join(10.0)
        assert not first.is_alive()
        runner.start("ref", lambda: None, call=(iter_reference_raster, scene, SIZE))
        runner._thread.join(120.0)
        assert not runner.error and runner.snapshot()[0].fraction == 1.0
        assert WorkerProcess.spawns == before + 2 and runner.worker.process is not first
        assert runner.worker.process.is_alive()
    finally:
        runner.shutdown()
    assert runner.worker.process is None


def test_each_level_step_streams_before_the_next_one_is_computed():
    """The step that completes the first full-resolution pass is handed on at once (it used
    to wait for the next chunk); the last step comes again, marked done, with its image."""
    from shadelab.pipelines.progressive import held_back

    made = []

    def steps():
        for i in range(4):
            made.append(i)
            yield Progress(np.full((2, 2, 3), i, np.float32), (i + 1) / 4, f"step {i}",
                           {"level": 1})

    out = held_back(steps())
    for i in range(4):
        step = next(out)
        assert step.message == f"step {i}" and len(made) == i + 1   # nothing computed ahead
        assert not step.stats.get("done")
    final = next(out)
    assert final.stats["done"] and final.fraction == 1.0 and final.message == "done: step 3"
    np.testing.assert_array_equal(final.image, np.full((2, 2, 3), 3, np.float32))
    assert list(out) == []
    assert list(held_back(iter(()))) == []


def test_a_process_jobs_last_image_is_prepared_off_the_ui_thread():
    """``JobRunner.prepare`` runs in the listener thread (the viewer converts each image to
    sRGB there, not on the UI thread): when the job has ended, ``prepared`` holds the
    conversion of its last image, with that Progress's version, stats and message."""
    from shadelab.shading.conventions import to_srgb8
    from shadelab.ui.pipelines import SrgbOffThread

    scene = load_preset("cornell")
    runner = JobRunner()
    convert = SrgbOffThread()
    convert.exposure = 0.5
    runner.prepare = convert
    try:
        runner.start("ref", lambda: None, call=(iter_reference_raster, scene, SIZE))
        assert runner.in_process
        runner._thread.join(120.0)
        assert not runner.running and not runner.error
        last, version = runner.snapshot()
        seen_version, (exposure, rgba, image), stats, message = runner.prepared
        assert seen_version == version and stats is last.stats and message == last.message
        assert exposure == 0.5 and image.shape == (SIZE[1], SIZE[0], 3)
        np.testing.assert_array_equal(image, last.image)
        assert rgba.shape == (SIZE[1], SIZE[0], 4) and rgba.flags.c_contiguous
        np.testing.assert_array_equal(rgba[..., :3], to_srgb8(last.image, 0.5)[::-1])
        assert (rgba[..., 3] == 255).all()
    finally:
        runner.shutdown()
