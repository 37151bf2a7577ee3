import imageio.v2 as imageio
import numpy as np
import pytest

from roto.cli import main
from roto.eval.video import TOUCH_RGBA


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
