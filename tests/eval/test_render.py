import imageio.v2 as imageio
import numpy as np
import pytest

from roto.cli import main
from roto.eval.video import HARD_TOUCH_RGBA, HARD_TOUCH_VALUE, TOUCH_RGBA, force_touch_rgba


def cyan_pixels(image):
    r, g, b = (image[..., i].astype(np.int16) for i in range(3))
    return int(((b - r > 50) & (g - r > 50) & (np.abs(g - b) < 60)).sum())


@pytest.mark.parametrize("task", ["bounce", "baoding"])
def test_render_writes_a_picture_with_the_touching_links_coloured(task, tmp_path):
    out = tmp_path / f"{task}.png"
    assert main(["render", "--task", task, "--out", str(out), "--settle_steps", "30"]) == 0
    image = imageio.imread(out)
    assert image.shape == (480, 640, 3) and image.std() > 5
    # the resting ball(s) touch the palm, so some pixels carry the (shaded) cyan contact colour,
    # which nothing else in the scene has: the grey hand, red / blue / orange balls, green backdrop
    assert TOUCH_RGBA[0] < 0.1 and min(TOUCH_RGBA[1], TOUCH_RGBA[2]) > 0.8
    assert cyan_pixels(image) > 200


def test_nothing_is_cyan_before_the_ball_lands(tmp_path):
    out = tmp_path / "early.png"
    assert main(["render", "--task", "bounce", "--out", str(out), "--settle_steps", "1"]) == 0
    assert cyan_pixels(imageio.imread(out)) < 20


def test_render_unknown_robot_is_a_clear_error(tmp_path, capsys):
    assert main(["render", "--robot", "leap", "--out", str(tmp_path / "x.png")]) == 2
    assert "unknown robot 'leap'" in capsys.readouterr().err
    assert not (tmp_path / "x.png").exists()


def test_force_touch_colours_run_from_cyan_to_red():
    rgba = force_touch_rgba(np.array([1e-6, HARD_TOUCH_VALUE / 2, HARD_TOUCH_VALUE, 50.0]))
    np.testing.assert_allclose(rgba[0], TOUCH_RGBA, atol=1e-5)
    np.testing.assert_allclose(rgba[1], (TOUCH_RGBA + HARD_TOUCH_RGBA) / 2, atol=1e-6)
    np.testing.assert_allclose(rgba[2], HARD_TOUCH_RGBA)
    np.testing.assert_allclose(rgba[3], HARD_TOUCH_RGBA)  # capped


def test_render_with_force_touch_colours_links_by_their_force(tmp_path):
    paths = {touch: tmp_path / f"{touch}.png" for touch in ("binary", "force")}
    for touch, path in paths.items():
        assert main(["render", "--task", "baoding", "--touch", touch, "--out", str(path), "--settle_steps", "30"]) == 0
    binary, force = (imageio.imread(path) for path in paths.values())
    # the palm carries both balls: cyan with binary touch, pressed towards red with force touch
    assert cyan_pixels(binary) > 200
    assert cyan_pixels(force) < cyan_pixels(binary) / 2


def yellow_pixels(image):
    r, g, b = (image[..., i].astype(np.int16) for i in range(3))
    return int(((r - b > 60) & (g - b > 50) & (np.abs(r - g) < 60)).sum())


def test_render_with_taxel_touch_draws_the_pressed_taxels(tmp_path):
    counts = {}
    for touch in ("binary", "taxels"):
        out = tmp_path / f"{touch}.png"
        args = ["render", "--robot", "allegro", "--touch", touch, "--out", str(out), "--settle_steps", "60"]
        assert main(args) == 0
        counts[touch] = yellow_pixels(imageio.imread(out))
    assert counts["binary"] < 20 < counts["taxels"]


def test_baoding_pictures_draw_each_ball_s_current_target():
    import roto
    from roto.eval.video import TactileFrameRenderer
    from roto.tasks.baoding import SUCCESS_RADIUS

    env = roto.make("baoding", robot="shadow", num_envs=1)
    env.reset()
    env.task_state.swapped[0] = True  # ball a now aims at the second target
    renderer = TactileFrameRenderer(env, 160, 120)
    renderer.render()
    scene = renderer.renderer.scene
    spheres = [scene.geoms[i] for i in range(scene.ngeom)][-2:]
    targets = env.task_state.targets.numpy()
    np.testing.assert_allclose([g.pos for g in spheres], targets[::-1], atol=1e-6)
    assert all(g.size[0] == pytest.approx(SUCCESS_RADIUS) and g.rgba[3] < 1 for g in spheres)
    renderer.close()
    env.close()
