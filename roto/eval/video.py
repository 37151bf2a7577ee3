"""Render episodes of a policy offscreen into an mp4 (no display needed).

Tactile links are drawn in a contact colour while their touch bit is on; with force touch, in a
colour running from cyan (a light touch) to red (10 N or more) with the link's force; with taxel
touch, the pressed taxels are drawn as yellow boxes as well.
"""

from __future__ import annotations

import pathlib

import mujoco
import numpy as np
import torch

from roto.cli_errors import check_output_path, make_parents
from roto.envs.observations import FORCE_SCALE, tactile_frame
from roto.envs.roto_env import RotoEnv
from roto.rl.build import check_policy_fits
from roto.rl.networks import ActorCritic
from roto.rl.run_spec import RunSpec
from roto.sim.scene import TAXEL_SITE_GROUP

TOUCH_RGBA = np.array([0.0, 0.85, 1.0, 1.0], dtype=np.float32)
"""Colour of a tactile link while its bit is on (cyan), and of the lightest force touch."""
HARD_TOUCH_RGBA = np.array([1.0, 0.15, 0.05, 1.0], dtype=np.float32)
"""Colour of a tactile link pressed with ``HARD_TOUCH_VALUE`` or more (red), with force touch."""
TAXEL_RGBA = np.array([1.0, 0.85, 0.0, 1.0], dtype=np.float32)
"""Colour of a pressed taxel (yellow); the others are not drawn."""
HARD_TOUCH_VALUE = float(np.log1p(10.0 / FORCE_SCALE))
"""The force touch value (10 N) drawn fully in ``HARD_TOUCH_RGBA``."""
FPS = 60
"""One frame per control step (60 Hz), so the video plays in real time."""
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg")
"""The picture formats ``render_scene`` writes."""


def _camera() -> mujoco.MjvCamera:
    camera = mujoco.MjvCamera()
    camera.lookat[:] = (0.03, 0.0, 0.02)
    camera.distance = 0.42
    camera.azimuth = 150.0
    camera.elevation = -30.0
    return camera


def force_touch_rgba(values: np.ndarray) -> np.ndarray:
    """Colours (n, 4) of force touch ``values`` (n,) > 0: from ``TOUCH_RGBA`` to ``HARD_TOUCH_RGBA``."""
    share = np.clip(np.asarray(values, dtype=np.float32) / HARD_TOUCH_VALUE, 0.0, 1.0)[:, None]
    return (1.0 - share) * TOUCH_RGBA + share * HARD_TOUCH_RGBA


class TactileFrameRenderer:
    """Renders world 0 of an env, colouring the geoms of its touching tactile links."""

    def __init__(self, env: RotoEnv, width: int = 640, height: int = 480) -> None:
        self.env = env
        self.model = env.model
        self.data = mujoco.MjData(self.model)
        self.renderer = mujoco.Renderer(self.model, height=height, width=width)
        self.camera = _camera()
        self._base_rgba = self.model.geom_rgba.copy()
        self._base_site_rgba = self.model.site_rgba.copy()
        self._taxel_sites = np.array(
            [
                self.model.sensor_objid[i]
                for i in range(self.model.nsensor)
                if self.model.sensor_type[i] == mujoco.mjtSensor.mjSENS_TOUCH
            ],
            dtype=np.int64,
        )
        self._option = mujoco.MjvOption()
        self._option.sitegroup[TAXEL_SITE_GROUP] = 1
        body_ids = [self.model.body(link).id for link in env.robot.tactile_links]
        self._link_geoms = [np.flatnonzero(self.model.geom_bodyid == b) for b in body_ids]

    def render(self) -> np.ndarray:
        """(height, width, 3) uint8 of world 0, touching links coloured (as the env reads touch)."""
        mujoco.mj_setState(
            self.model, self.data, self.env.backend.physics_state()[0], mujoco.mjtState.mjSTATE_FULLPHYSICS
        )
        mujoco.mj_forward(self.model, self.data)
        values, pressed = self._touch()
        self.model.geom_rgba[:] = self._base_rgba
        for geoms, rgba in zip(self._link_geoms, self._touch_colours(values), strict=True):
            if rgba is not None:
                self.model.geom_rgba[geoms] = rgba
        self.model.site_rgba[self._taxel_sites] = 0.0  # only pressed taxels are drawn
        self.model.site_rgba[self._taxel_sites[pressed]] = TAXEL_RGBA
        self.renderer.update_scene(self.data, camera=self.camera, scene_option=self._option)
        self._add_markers()
        return self.renderer.render().copy()

    def _add_markers(self) -> None:
        """Append the task's markers of world 0 (e.g. Baoding's targets) to the scene as spheres."""
        scene = self.renderer.scene
        for marker in self.env.task.markers(self.env.task_state):
            if scene.ngeom >= scene.maxgeom:
                return
            mujoco.mjv_initGeom(
                scene.geoms[scene.ngeom],
                mujoco.mjtGeom.mjGEOM_SPHERE,
                np.array([marker.radius, 0.0, 0.0]),
                marker.pos[0].detach().cpu().numpy().astype(np.float64),
                np.eye(3).flatten(),
                np.array(marker.rgba, dtype=np.float32),
            )
            scene.ngeom += 1

    def _touch(self) -> tuple[np.ndarray, np.ndarray]:
        """(per tactile link its touch value, per taxel whether it is pressed) after ``mj_forward``,
        read as the env reads them (``tactile_frame`` of the env's sensor columns)."""
        env, sensors = self.env, torch.from_numpy(self.data.sensordata)[None]
        links = env.indices.tactile_force.take(sensors)
        values = tactile_frame(env.config.touch, links, env.indices.taxels.take(sensors), env.config.tactile_threshold)
        n_links = len(env.robot.tactile_links)
        return values[0, :n_links].numpy(), values[0, n_links:].numpy() > 0

    def _touch_colours(self, values: np.ndarray) -> list[np.ndarray | None]:
        """Per tactile link, its colour if it is touching, else None."""
        colours = force_touch_rgba(values) if self.env.config.touch == "force" else [TOUCH_RGBA] * len(values)
        return [rgba if value > 0 else None for value, rgba in zip(values, colours, strict=True)]

    def close(self) -> None:
        """Free the GL context and restore the colours."""
        self.model.geom_rgba[:] = self._base_rgba
        self.model.site_rgba[:] = self._base_site_rgba
        self.renderer.close()


@torch.no_grad()
def record_video(
    model: ActorCritic,
    spec: RunSpec,
    path: str | pathlib.Path,
    steps: int = 600,
    seed: int = 0,
    width: int = 640,
    height: int = 480,
) -> dict[str, float]:
    """Write ``steps`` control steps of world 0 (episodes restart when they end) to ``path`` (mp4).

    Returns the number of frames and the return, and task metrics of the episodes that finished.
    """
    import imageio.v2 as imageio

    if steps < 1:
        raise ValueError(f"video length must be >= 1 step, got {steps}")
    path = check_output_path(path, "video path", example="play.mp4")
    env = RotoEnv(spec.cpu_env_config(num_envs=1, seed=seed))
    check_policy_fits(model, env)
    renderer = TactileFrameRenderer(env, width, height)
    obs_dict, _ = env.reset(seed=seed)
    frames = 0
    finished: list[dict[str, float]] = []
    make_parents(path)  # the folders of a new path, now that the env is built
    writer = imageio.get_writer(str(path), format="FFMPEG", fps=FPS, codec="libx264", quality=7, macro_block_size=8)
    try:
        for _ in range(steps):
            obs_dict, _, _, _, info = env.step(model.act_deterministic(obs_dict))
            writer.append_data(renderer.render())
            frames += 1
            if "episode" in info and bool(info["_episode"][0]):
                finished.append({k: float(v[0]) for k, v in info["episode"].items()})
    finally:
        writer.close()
        renderer.close()
        env.close()
    return {"frames": frames, "episodes": finished}


def render_scene(
    task: str,
    robot: str,
    path: str | pathlib.Path,
    settle_steps: int = 60,
    seed: int = 0,
    width: int = 640,
    height: int = 480,
    touch: str = "binary",
) -> pathlib.Path:
    """A PNG of ``robot`` in ``task``'s scene after ``settle_steps`` steps holding the default pose.

    The hand holds its default (cupped) pose with no reset noise, so the picture shows where the
    objects come to rest; touching links are drawn in the contact colour (with ``touch="force"``,
    coloured by their force).
    """
    import imageio.v2 as imageio

    from roto.envs.config import EnvConfig

    if settle_steps < 0:
        raise ValueError(f"settle_steps must be >= 0 control steps, got {settle_steps}")
    path = check_output_path(path, "image path", example="scene.png")
    if path.suffix.lower() not in IMAGE_SUFFIXES:
        raise ValueError(f"image path {str(path)!r}: give a file ending in one of {list(IMAGE_SUFFIXES)}")
    env = RotoEnv(EnvConfig(task=task, robot=robot, num_envs=1, seed=seed, reset_joint_noise=0.0, touch=touch))
    env.reset(seed=seed)
    hold = env.hold_action()
    for _ in range(settle_steps):
        env.step(hold)
    renderer = TactileFrameRenderer(env, width, height)
    try:
        imageio.imwrite(make_parents(path), renderer.render())
    finally:
        renderer.close()
        env.close()
    return path
