"""The lesson prefetch (shadelab.lab.prefetch): the next step's offline job is asked for at
the right time, and its result is taken when the key matches, dropped when not."""

from types import SimpleNamespace

from shadelab.lab.lesson_file import LessonRun
from shadelab.lab.prefetch import Prefetch, next_offline, step_key, unedited

OFFLINE = ("raytrace", "pathtrace", "radiosity")


class FakeRunner:
    def __init__(self):
        self.running, self.cancelled, self.started = False, 0, []

    def cancel(self, **_):
        self.cancelled += 1
        self.running = False


def lesson(*pipelines):
    steps = [SimpleNamespace(pipeline=p, title="", caption="") for p in pipelines]
    return LessonRun(SimpleNamespace(steps=steps))


def starter(pf, runner):
    def start(wanted):
        pf.runner = pf.runner or runner
        runner.running = True
        runner.started.append(wanted)
    return start


def test_next_offline_is_the_step_after_the_current_one():
    run = lesson("phong", "phong", "raytrace", "pathtrace", "radiosity")
    run.index = 0
    assert next_offline(run, OFFLINE) is None              # step 2 is raster
    run.index = 1
    assert next_offline(run, OFFLINE) == (2, "raytrace")
    run.index = 2
    assert next_offline(run, OFFLINE) == (3, "pathtrace")
    run.index = 3
    assert next_offline(run, OFFLINE) == (4, "radiosity")
    run.index = 4
    assert next_offline(run, OFFLINE) is None              # the last step
    assert next_offline(None, OFFLINE) is None


def test_prefetch_waits_for_the_current_step_then_starts_once():
    run = lesson("raytrace", "pathtrace")
    run.index = 0
    pf, runner = Prefetch(), FakeRunner()
    key = step_key(run, 1, "pathtrace", (1024, 768), 4)
    wanted = (key, 1, "pathtrace", (1024, 768))
    assert not pf.tick(wanted, True, starter(pf, runner))   # current step still refining
    assert runner.started == []
    assert pf.tick(wanted, False, starter(pf, runner))
    assert runner.started == [wanted] and pf.key == key and pf.index == 1
    assert not pf.tick(wanted, False, starter(pf, runner))  # never twice
    assert len(runner.started) == 1


def test_prefetch_yields_to_a_busy_current_step():
    run = lesson("raytrace", "pathtrace")
    run.index = 0
    pf, runner = Prefetch(), FakeRunner()
    wanted = (step_key(run, 1, "pathtrace", (64, 48), 4), 1, "pathtrace", (64, 48))
    pf.tick(wanted, False, starter(pf, runner))
    pf.tick(wanted, True, starter(pf, runner))     # the teacher edits the current step
    assert runner.cancelled == 1 and pf.key is None


def test_a_prefetch_that_no_longer_matches_is_cancelled():
    run = lesson("phong", "raytrace", "pathtrace")
    run.index = 0
    pf, runner = Prefetch(), FakeRunner()
    wanted = (step_key(run, 1, "raytrace", (64, 48), 4), 1, "raytrace", (64, 48))
    pf.tick(wanted, False, starter(pf, runner))
    pf.tick(None, False, starter(pf, runner))      # the teacher went back (no next offline)
    assert runner.cancelled == 1 and pf.key is None
    pf.tick(wanted, False, starter(pf, runner))
    resized = (step_key(run, 1, "raytrace", (80, 60), 4), 1, "raytrace", (80, 60))
    pf.tick(resized, False, starter(pf, runner))   # the viewport changed size: a new one
    assert runner.cancelled == 2 and pf.key == resized[0]


def test_the_result_is_taken_when_the_key_matches_and_not_otherwise():
    run = lesson("phong", "raytrace")
    run.index = 0
    pf, runner, own = Prefetch(), FakeRunner(), FakeRunner()
    key = step_key(run, 1, "raytrace", (64, 48), 4)
    pf.tick((key, 1, "raytrace", (64, 48)), False, starter(pf, runner))
    assert pf.take(step_key(run, 1, "raytrace", (80, 60), 4), own) is None   # other size
    assert pf.take(step_key(lesson("phong", "raytrace"), 1, "raytrace", (64, 48), 4),
                   own) is None                                              # other lesson
    assert pf.take(key, own) is runner            # partial or finished: the runner itself
    assert pf.runner is own and pf.key is None    # the viewport's idle runner is kept
    assert pf.take(key, own) is None              # taken once


def test_keys_what_the_image_depends_on():
    run = lesson("phong", "pathtrace", "radiosity")
    assert step_key(run, 1, "pathtrace", (64, 48), 4) != step_key(run, 1, "pathtrace",
                                                                   (64, 48), 8)
    assert step_key(run, 1, "raytrace", (64, 48), 4) == step_key(run, 1, "raytrace",
                                                                 (64, 48), 8)
    assert step_key(run, 2, "radiosity", (64, 48), 4) == step_key(run, 2, "radiosity",
                                                                  (80, 60), 4)


def test_an_edited_step_is_not_the_prefetched_one():
    run = lesson("raytrace")
    state = SimpleNamespace(scene_version=3, scene=SimpleNamespace(version=10))
    run.loaded = (3, 10)
    assert unedited(run, state)
    state.scene.version = 11
    assert not unedited(run, state)
    assert not unedited(None, state)


def test_go_to_records_the_loaded_scene():
    from shadelab.lab.lesson import go_to, load_lesson
    from shadelab.lab.state import AppState
    from shadelab.scene.preset import load_preset

    state = AppState.from_scene(load_preset("lecture"), "lecture")
    state.walk.lesson = LessonRun(load_lesson("phong-to-radiosity"))
    assert go_to(state, 11)
    assert state.walk.lesson.step.pipeline == "raytrace"
    assert unedited(state.walk.lesson, state)
    state.scene.render.exposure = state.scene.render.exposure + 0.5
    assert not unedited(state.walk.lesson, state)


def test_a_new_prefetch_waits_for_the_dropped_one_to_stop():
    run = lesson("phong", "raytrace", "pathtrace")
    run.index = 0
    pf, runner = Prefetch(), FakeRunner()
    pf.runner = runner
    runner.running = True          # a cancelled job has not stopped yet
    wanted = (step_key(run, 1, "raytrace", (64, 48), 4), 1, "raytrace", (64, 48))
    assert not pf.tick(wanted, False, starter(pf, runner))
    runner.running = False
    assert pf.tick(wanted, False, starter(pf, runner))
