"""VAO (Szirmay-Kalos et al. 2010 as outlined in VAO++ §3) through the registry: the pipe
model on a synthetic configuration, what it reads. Open planes, threads, settings and their
docs table: test_conformance.py."""
import numpy as np

import aolab


def test_parallel_pipes_are_the_papers_and_exact_facing_the_camera():
    # Pipes parallel to the view axis (view_ray_pipes=False, F by eq. 2): a plane facing the
    # camera is open, a tilted plane off-axis occludes itself a little (perspective).
    g = aolab.analytic_scene("plane", 192, 108)
    assert aolab.compute("vao", g, radius=0.5, view_ray_pipes=False)[g.valid_mask()].min() > 0.9999
    t = aolab.analytic_scene("plane", 192, 108, tilt=60, fov=90)
    assert aolab.compute("vao", t, radius=0.5, view_ray_pipes=False)[t.valid_mask()].min() < 0.99


def test_one_occluder_in_each_pipe_case():
    # A plane at depth 5 facing the camera, P on the view axis, R = 1: sphere centre at depth
    # 4.5, radius 0.5. Samples with random rotation fill the disc; an occluding block over
    # the left half of the disc at depth d gives: d > 5 - nothing (B); d = 4.5 - roughly half
    # of the left half's volume open (A); d = 3.9 - the left half closed (C).
    h = w = 101
    depth = np.full((h, w), 5.0, np.float32)
    normal = np.zeros((h, w, 3), np.float32)
    normal[..., 2] = 1

    def ao_at_centre(block_depth):
        d = depth.copy()
        d[:, :50] = block_depth
        g = aolab.GBuffer(d, normal, fx=100, fy=100, cx=50.5, cy=50.5)
        return aolab.compute("vao", g, radius=1.0, samples=64, view_ray_pipes=False,
                             random_rotation=False)[50, 50]

    assert ao_at_centre(5.0) == 1.0
    assert 0.6 < ao_at_centre(4.5) < 0.9
    assert 0.45 < ao_at_centre(3.9) < 0.55


def test_registry_entry():
    info = aolab.method_info("vao")
    assert info["needs_normal"] is True and info["needs_color"] is False
