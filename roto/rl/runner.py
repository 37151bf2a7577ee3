"""The training loop: rollouts, PPO updates, evaluation envs, logging, checkpoints and exact resume."""

from __future__ import annotations

import contextlib
import dataclasses
import math
import pathlib
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import torch
import yaml
from tqdm import tqdm

from roto.envs.config import EnvConfig
from roto.envs.roto_env import RotoEnv
from roto.rl.config import AgentConfig, from_dict, to_dict
from roto.rl.logger import ScalarLogger
from roto.rl.networks import ActorCritic
from roto.rl.ppo import PPO
from roto.rl.storage import RolloutBuffer

CONFIG_NAME = "config.yaml"
CHECKPOINT_DIR = "checkpoints"
EVAL_SEED_OFFSET = 10_000
"""Evaluation envs are seeded with seed + this, so they never replay the training envs' resets."""


@dataclass(frozen=True, kw_only=True)
class TrainSettings:
    """What a training run trains on (the training envs' config) and for how many env steps."""

    env: EnvConfig
    total_steps: int = 1_000_000

    def env_config(self, num_envs: int | None = None, seed: int | None = None, **changes: Any) -> EnvConfig:
        """The training envs' config, or that of other envs (another num_envs / seed / backend ...)."""
        changes.update({name: value for name, value in (("num_envs", num_envs), ("seed", seed)) if value is not None})
        return dataclasses.replace(self.env, **changes)

    def cpu_env_config(self, num_envs: int | None = None, seed: int | None = None) -> EnvConfig:
        """As ``env_config``, on the CPU backend: evaluation and videos of any run, GPU-trained too."""
        return self.env_config(num_envs, seed, backend="cpu", device="cpu")

    def to_dict(self) -> dict[str, Any]:
        """Plain nested dict (for config.yaml and checkpoints)."""
        return {"env": dataclasses.asdict(self.env), "total_steps": self.total_steps}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TrainSettings:
        """Inverse of ``to_dict``."""
        return cls(env=EnvConfig(**data["env"]), total_steps=int(data["total_steps"]))


@contextlib.contextmanager
def single_torch_thread(device: torch.device) -> Iterator[None]:
    """Run the block with one torch CPU thread, then restore the previous count.

    Rollouts on the CPU backend share the cores with MuJoCo's stepping threads; a second torch
    (OpenMP) thread busy-waiting after the policy's small matrix products steals time from them
    (measured: 0.52 s instead of 0.39 s of simulation per 4096 steps). Used around every loop that
    alternates policy and env steps (training rollouts, ``evaluate``); the PPO update keeps the
    configured count. No effect on CUDA devices.
    """
    if device.type != "cpu":
        yield
        return
    previous = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(previous)


def flatten_obs(obs: dict[str, torch.Tensor]) -> torch.Tensor:
    """Concatenate the observation groups (in the env's group order) into (B, D) float32."""
    return torch.cat([value.to(torch.float32) for value in obs.values()], dim=-1)


def write_run_config(run_dir: pathlib.Path, settings: TrainSettings, agent: AgentConfig) -> None:
    """The resolved config of a run (what ``--resume`` reads back)."""
    data = {"train": settings.to_dict(), "agent": to_dict(agent)}
    (run_dir / CONFIG_NAME).write_text(yaml.safe_dump(data, sort_keys=False))


def read_run_config(run_dir: pathlib.Path) -> tuple[TrainSettings, AgentConfig]:
    """Inverse of ``write_run_config``."""
    path = run_dir / CONFIG_NAME
    if not path.is_file():
        raise FileNotFoundError(f"{str(run_dir)!r} is not a roto run directory (no {CONFIG_NAME})")
    data = yaml.safe_load(path.read_text())
    return TrainSettings.from_dict(data["train"]), from_dict(AgentConfig, data["agent"]).validate()


def build_model(env: RotoEnv, agent: AgentConfig) -> ActorCritic:
    """The actor-critic for ``env``'s flat observation and action sizes."""
    obs_dim = sum(size * env.config.frame_stack for size in env.frame_sizes.values())
    net = agent.network
    return ActorCritic(
        obs_dim,
        env.num_actions,
        encoder=net.encoder,
        policy_head=net.policy_head,
        value_head=net.value_head,
        init_log_std=net.init_log_std,
        obs_normalization=net.obs_normalization,
    )


class EvalRounds:
    """Collects finished evaluation episodes; a round closes after ``size`` episodes."""

    def __init__(self, size: int, metric_names: tuple[str, ...]) -> None:
        self.size, self.metric_names = size, metric_names
        self.pending: dict[str, list[float]] = {"return": [], "length": [], **{m: [] for m in metric_names}}

    def add(self, info: dict[str, Any]) -> dict[str, float] | None:
        """Fold in one step's ``info``; the round's statistics when it closes, else None."""
        if "episode" not in info:
            return None
        done = info["_episode"]
        episode = info["episode"]
        self.pending["return"] += episode["r"][done].tolist()
        self.pending["length"] += episode["l"][done].to(torch.float64).tolist()
        for m in self.metric_names:
            self.pending[m] += episode[m][done].tolist()
        if len(self.pending["return"]) < self.size:
            return None
        stats: dict[str, float] = {}
        for name, values in self.pending.items():
            t = torch.tensor(values[: self.size], dtype=torch.float64)
            stats[f"eval/{name}_mean"] = float(t.mean())
            stats[f"eval/{name}_std"] = float(t.std(unbiased=False))
        self.pending = {name: values[self.size :] for name, values in self.pending.items()}
        return stats


class Trainer:
    """PPO on B training envs with a separate set of deterministic evaluation envs.

    Args:
        settings: task, robot, obs mode, env count, step budget, seed, backend.
        agent: network, PPO and run settings.
        run_dir: where config, logs and checkpoints go (created).
        tensorboard: also write TensorBoard event files.
        env_factory: builds an env from an ``EnvConfig`` (default ``RotoEnv``); tests pass a toy env
            with the same interface.
    """

    def __init__(
        self,
        settings: TrainSettings,
        agent: AgentConfig,
        run_dir: str | pathlib.Path,
        tensorboard: bool = True,
        env_factory: Callable[[EnvConfig], Any] = RotoEnv,
    ) -> None:
        self.settings, self.agent = settings, agent
        self.run_dir = pathlib.Path(run_dir)
        (self.run_dir / CHECKPOINT_DIR).mkdir(parents=True, exist_ok=True)
        self.env = env_factory(settings.env_config())
        self.num_eval_envs = agent.run.num_eval_envs_gpu if self.env.device.type == "cuda" else agent.run.num_eval_envs
        self.eval_env = env_factory(
            settings.env_config(num_envs=self.num_eval_envs, seed=settings.env.seed + EVAL_SEED_OFFSET)
        )
        self.device = self.env.device  # the policy learns where the envs simulate
        torch.manual_seed(settings.env.seed)
        self.model = build_model(self.env, agent).to(self.device)
        self.ppo = PPO(self.model, agent.ppo)
        self.generator = torch.Generator(device=self.device).manual_seed(settings.env.seed)
        obs_dim = self.model.encoder[0].in_features
        self.buffer = RolloutBuffer(
            agent.ppo.rollouts, settings.env.num_envs, obs_dim, self.env.num_actions, self.device
        )
        self.eval_rounds = EvalRounds(self.num_eval_envs, self.env.task.metric_names)
        self.update = 0
        self.env_steps = 0
        self.best_eval_return = -math.inf
        self.train_seconds = 0.0  # rollouts + updates so far, summed over resumes (not logging/checkpoints)
        self.last_eval: dict[str, float] = {}
        self.obs: torch.Tensor | None = None
        self.eval_obs: torch.Tensor | None = None
        self.tensorboard = tensorboard
        self.plot = tensorboard  # quick tests turn both off
        write_run_config(self.run_dir, settings, agent)

    @property
    def steps_per_update(self) -> int:
        """Env steps collected per PPO update (rollouts x num_envs)."""
        return self.agent.ppo.rollouts * self.settings.env.num_envs

    @property
    def total_updates(self) -> int:
        """Updates needed for the step budget (at least one)."""
        return max(1, math.ceil(self.settings.total_steps / self.steps_per_update))

    # ------------------------------------------------------------------------ rollouts

    def _start(self) -> None:
        if self.obs is None:
            self.obs = flatten_obs(self.env.reset(seed=self.settings.env.seed)[0])
            self.eval_obs = flatten_obs(self.eval_env.reset(seed=self.settings.env.seed + EVAL_SEED_OFFSET)[0])

    @torch.no_grad()
    def _collect(self) -> tuple[dict[str, float], list[dict[str, float]]]:
        """Fill the buffer with one rollout; (timings and training-episode stats, closed eval rounds)."""
        cfg = self.agent.ppo
        t_inference = t_sim = 0.0
        train_episodes: dict[str, list[float]] = {}
        rounds = []
        for _ in range(cfg.rollouts):
            t0 = time.perf_counter()
            mean, log_std, value_head = self.model(self.obs)
            std = log_std.exp().expand_as(mean)
            action = mean + std * torch.randn(mean.shape, generator=self.generator, device=self.device)
            log_prob = torch.distributions.Normal(mean, std).log_prob(action).sum(-1)
            value = self.ppo.values(value_head)
            eval_action = self.model.act_deterministic(self.eval_obs)
            t1 = time.perf_counter()
            next_obs, reward, terminated, truncated, info = self.env.step(action)
            eval_next, _, _, _, eval_info = self.eval_env.step(eval_action)
            t2 = time.perf_counter()
            reward = reward.clone()
            if cfg.bootstrap_timeouts and "final_obs" in info:
                final_values = self.ppo.values(self.model(flatten_obs(info["final_obs"]))[2])
                reward += cfg.gamma * final_values * truncated.to(reward.dtype)
            self.buffer.add(self.obs, action, log_prob, value, reward, terminated | truncated)
            if "episode" in info:
                done = info["_episode"]
                for name in ("r", "l", *self.env.task.metric_names):
                    train_episodes.setdefault(name, []).extend(info["episode"][name][done].to(torch.float64).tolist())
            closed = self.eval_rounds.add(eval_info)
            if closed is not None:
                rounds.append(closed)
            self.obs = flatten_obs(next_obs)
            self.eval_obs = flatten_obs(eval_next)
            t_inference += t1 - t0
            t_sim += t2 - t1
        stats = {"perf/inference_s": t_inference, "perf/simulation_s": t_sim}
        for name, values in train_episodes.items():
            tag = {"r": "return", "l": "length"}.get(name, name)
            stats[f"train/episode_{tag}"] = sum(values) / len(values)
        return stats, rounds

    # ------------------------------------------------------------------------ training

    def train(self, progress: bool = True) -> dict[str, float]:
        """Train until the step budget; returns the last evaluation round's statistics ({} if none closed)."""
        self._start()
        logger = ScalarLogger(self.run_dir, tensorboard=self.tensorboard)
        bar = tqdm(
            total=self.total_updates * self.steps_per_update,
            initial=self.env_steps,
            disable=not progress,
            unit="step",
            desc=f"{self.settings.env.task}/{self.settings.env.robot}/{self.settings.env.obs_mode}",
        )
        try:
            while self.update < self.total_updates:
                t_start = time.perf_counter()
                with single_torch_thread(self.device):
                    stats, rounds = self._collect()
                t_update = time.perf_counter()
                last_values = self.ppo.values(self.model(self.obs)[2].detach())
                self.ppo.finish_rollout(self.buffer, last_values)
                metrics = self.ppo.update(self.buffer, self.generator)
                if self.model.obs_scaler is not None:
                    self.model.obs_scaler.update(self.buffer.obs.flatten(0, 1))
                self.buffer.clear()
                t_end = time.perf_counter()
                self.update += 1
                self.env_steps += self.steps_per_update
                scalars = {f"ppo/{k}": v for k, v in metrics.items()}
                scalars.update(stats)
                scalars["perf/update_s"] = t_end - t_update
                scalars["perf/steps_per_s"] = self.steps_per_update / (t_end - t_start)
                self.train_seconds += t_end - t_start
                scalars["perf/train_wall_s"] = self.train_seconds
                for closed in rounds:
                    self._on_eval_round(closed)
                    scalars.update(closed)
                logger.log(scalars, self.env_steps, self.update)
                if self.update % self.agent.run.checkpoint_every == 0 or self.update == self.total_updates:
                    self.save(self.run_dir / CHECKPOINT_DIR / "latest.pt")
                    if self.update % self.agent.run.checkpoint_every == 0:
                        self.save(self.run_dir / CHECKPOINT_DIR / f"agent_{self.update}.pt")
                bar.update(self.steps_per_update)
                postfix = {"steps/s": f"{scalars['perf/steps_per_s']:.0f}"}
                if self.last_eval:
                    postfix["eval return"] = f"{self.last_eval['eval/return_mean']:.1f}"
                    for m in self.env.task.metric_names:
                        postfix[f"eval {m}"] = f"{self.last_eval[f'eval/{m}_mean']:.2f}"
                bar.set_postfix(postfix)
        finally:
            bar.close()
            logger.close()
        if self.plot:
            from roto.eval.plots import plot_learning_curve

            plot_learning_curve(self.run_dir)
        return dict(self.last_eval)

    def _on_eval_round(self, stats: dict[str, float]) -> None:
        self.last_eval = stats
        if stats["eval/return_mean"] > self.best_eval_return:
            self.best_eval_return = stats["eval/return_mean"]
            self.save(self.run_dir / CHECKPOINT_DIR / "best.pt")

    # ---------------------------------------------------------------------- checkpoints

    def state_dict(self) -> dict[str, Any]:
        """Everything needed to continue bit-identically."""
        return {
            "model": self.model.state_dict(),
            "ppo": self.ppo.state_dict(),
            "generator": self.generator.get_state(),
            "torch_rng": torch.get_rng_state(),
            "env": self.env.state_dict(),
            "eval_env": self.eval_env.state_dict(),
            "obs": self.obs,
            "eval_obs": self.eval_obs,
            "eval_pending": self.eval_rounds.pending,
            "update": self.update,
            "env_steps": self.env_steps,
            "best_eval_return": self.best_eval_return,
            "train_seconds": self.train_seconds,
            "last_eval": self.last_eval,
            "train": self.settings.to_dict(),
            "agent": to_dict(self.agent),
        }

    def save(self, path: pathlib.Path) -> None:
        """Write a checkpoint atomically (temporary file, then rename)."""
        tmp = path.with_suffix(".tmp")
        torch.save(self.state_dict(), tmp)
        tmp.replace(path)

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore a checkpoint written by ``save``."""
        self.model.load_state_dict(state["model"])
        self.ppo.load_state_dict(state["ppo"])
        self.generator.set_state(state["generator"].cpu())  # RNG states are CPU byte tensors
        torch.set_rng_state(state["torch_rng"].cpu())
        self.env.load_state_dict(state["env"])
        self.eval_env.load_state_dict(state["eval_env"])
        self.obs, self.eval_obs = state["obs"], state["eval_obs"]
        self.eval_rounds.pending = state["eval_pending"]
        self.update, self.env_steps = int(state["update"]), int(state["env_steps"])
        self.best_eval_return = float(state["best_eval_return"])
        self.train_seconds = float(state.get("train_seconds", 0.0))
        self.last_eval = dict(state["last_eval"])

    @classmethod
    def resume(
        cls,
        run_dir: str | pathlib.Path,
        total_steps: int | None = None,
        tensorboard: bool = True,
        env_factory: Callable[[EnvConfig], Any] = RotoEnv,
    ) -> Trainer:
        """A trainer continuing ``run_dir`` from its latest checkpoint (optionally with a new step budget)."""
        run_dir = pathlib.Path(run_dir)
        settings, agent = read_run_config(run_dir)
        checkpoint = run_dir / CHECKPOINT_DIR / "latest.pt"
        if not checkpoint.is_file():
            raise FileNotFoundError(f"no checkpoint to resume from: {str(checkpoint)!r} does not exist")
        if total_steps is not None:
            settings = dataclasses.replace(settings, total_steps=total_steps)
        trainer = cls(settings, agent, run_dir, tensorboard=tensorboard, env_factory=env_factory)
        trainer.load_state_dict(torch.load(checkpoint, weights_only=False, map_location=trainer.device))
        return trainer


def load_policy(checkpoint: str | pathlib.Path) -> tuple[ActorCritic, TrainSettings, AgentConfig]:
    """The policy stored in a checkpoint, with the run's settings."""
    path = pathlib.Path(checkpoint)
    if not path.is_file():
        raise FileNotFoundError(f"checkpoint {str(path)!r} does not exist")
    state = torch.load(path, weights_only=False, map_location="cpu")
    settings = TrainSettings.from_dict(state["train"])
    agent = from_dict(AgentConfig, state["agent"]).validate()
    env = RotoEnv(settings.cpu_env_config(num_envs=1))
    model = build_model(env, agent)
    env.close()
    model.load_state_dict(state["model"])
    model.eval()
    return model, settings, agent
