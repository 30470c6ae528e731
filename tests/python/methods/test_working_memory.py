"""The working-memory cache (core/base/working_memory.h): reused memory changes no bit of any
method's output, the cache holds what a computation gave back and lets it go when asked, its
limit is checked, and a second frame at 3840x2160 does not fault its arrays in again."""
import resource

import numpy as np
import pytest

import aolab

# 640 x 420: a float per pixel is just over 1 MiB, so every frame-sized array goes through the
# cache (smaller blocks go straight to malloc).
WIDTH, HEIGHT = 640, 420
# The screen-space limit's default 256 rays a pixel take minutes at this size; 4 exercise
# the same code.
FAST = {"screen_space_limit": {"rays": 4}}


@pytest.fixture(autouse=True)
def default_cache():
    """Every test starts and ends with an empty cache under the default limit."""
    limit = aolab.working_memory()["limit_bytes"]
    aolab.release_working_memory()
    yield
    aolab.set_working_memory_limit(limit)
    aolab.release_working_memory()


def bits(a: np.ndarray) -> bytes:
    return np.ascontiguousarray(a).view(np.uint32).tobytes()


@pytest.fixture(scope="module")
def scenes():
    """The scene the outputs are compared on, and another that leaves different values in the
    cached blocks."""
    return (aolab.analytic_scene("blocks", WIDTH, HEIGHT),
            aolab.analytic_scene("step", WIDTH, HEIGHT))


@pytest.mark.parametrize("method", aolab.methods())
def test_reused_memory_changes_no_bit(method, scenes):
    """The same bits from fresh memory, from blocks another scene left its values in, on 1 and
    2 threads, and after the cache is released: no code may rely on fresh pages' zeros."""
    g, other = scenes

    def run(gbuffer, threads):
        return bits(aolab.compute(method, gbuffer, radius=0.5, threads=threads,
                                  **FAST.get(method, {})))

    aolab.release_working_memory()
    fresh = run(g, 1)
    run(other, 2)  # the cache's blocks now hold another frame's values
    assert aolab.working_memory()["cached_bytes"] > 0
    assert run(g, 2) == fresh
    assert run(g, 1) == fresh
    aolab.release_working_memory()
    assert run(g, 2) == fresh


def test_the_cache_holds_what_a_computation_gave_back_until_released(scenes):
    g, _ = scenes
    before = aolab.working_memory()
    assert before["cached_bytes"] == 0 and before["cached_blocks"] == 0
    ao = aolab.compute("gtao", g, radius=0.5, threads=2)
    after = aolab.working_memory()
    # The depth copy and the prepared normals went back to the cache; the result (just over
    # 1 MiB) is held by the array and counted in use.
    assert after["cached_bytes"] >= 3 * WIDTH * HEIGHT * 4
    assert after["cached_bytes"] <= after["limit_bytes"]
    assert after["in_use_bytes"] >= ao.nbytes
    del ao
    assert aolab.working_memory()["cached_bytes"] > after["cached_bytes"]
    aolab.release_working_memory()
    assert aolab.working_memory()["cached_bytes"] == 0
    assert aolab.working_memory()["cached_blocks"] == 0


def test_a_limit_of_zero_keeps_nothing_and_a_limit_is_honoured(scenes):
    g, _ = scenes
    aolab.set_working_memory_limit(0)
    assert aolab.working_memory()["limit_bytes"] == 0
    aolab.compute("alchemy", g, radius=0.5, threads=2)
    assert aolab.working_memory()["cached_bytes"] == 0
    limit = 2 * WIDTH * HEIGHT * 4
    aolab.set_working_memory_limit(np.int64(limit))  # a numpy integer is a whole number too
    aolab.compute("sao", g, radius=0.5, threads=2)
    assert 0 < aolab.working_memory()["cached_bytes"] <= limit


@pytest.mark.parametrize("value, shown", [
    (-1, "-1 (int)"), (1.5, "1.5 (float)"), ("512", "'512' (str)"), (True, "True (bool)"),
    (None, "None (NoneType)"), (np.float64(2.0), "(float64)"), (np.bool_(True), "(bool"),
    (-2**70, "(int)"), (2**70, "(int)"),
])
def test_a_bad_limit_is_a_value_error_naming_it_and_the_value(value, shown):
    limit = aolab.working_memory()["limit_bytes"]
    with pytest.raises(ValueError, match="limit_bytes") as error:
        aolab.set_working_memory_limit(value)
    assert shown in str(error.value)
    assert aolab.working_memory()["limit_bytes"] == limit


def test_a_second_frame_at_3840x2160_faults_in_no_working_array():
    """Without the cache every working array of a 3840x2160 frame is fresh memory, one page
    fault per 4 KiB: Alchemy AO's depth copy, prepared normals and result (31.6 + 94.9 +
    31.6 MiB) are about 40 000 faults a frame. With the cache warm the second frame reuses
    them all; what faults remain (thread stacks, malloc's small blocks) are a few hundred. The
    bound, 5000, is below what a single fresh 3840x2160 float array costs (8100), so it fails
    if any of them is not reused."""
    g = aolab.analytic_scene("blocks", 3840, 2160)
    aolab.compute("alchemy", g, radius=0.5, threads=2)  # warms the cache; its result dropped
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    ao = aolab.compute("alchemy", g, radius=0.5, threads=2)
    faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
    assert ao.shape == (2160, 3840)
    assert faults < 5000, f"{faults} minor page faults in the second frame"
