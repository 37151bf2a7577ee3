"""The training loop: collect a rollout, update, evaluate, log, checkpoint. Read it top to bottom.

The learner (``roto.rl.ppo.PPO``) owns its transitions and its update; this file only
orchestrates them, the envs and the run directory.
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
import shutil
import time
from collections.abc import Callable
from typing import Any

import torch
from tqdm import tqdm

from roto.artifact_formats import format_stamp
from roto.envs.ball_paths import for_path_metrics
from roto.envs.config import EnvConfig
from roto.envs.contract import BatchedEnv
from roto.envs.roto_env import RotoEnv
from roto.rl.build import build_learner, build_model, extra_groups, stacked_sizes
from roto.rl.checkpoints import load_checkpoint, save_checkpoint
from roto.rl.episode_stats import EpisodeStats
from roto.rl.evaluation import PolicyEvaluator, best_eval_key, load_best_eval
from roto.rl.logger import ScalarLogger
from roto.rl.run_config import read_run_config, run_config, write_run_config
from roto.rl.run_dir import CHECKPOINT_DIR, RunDir, checkpoint_path, first_missing, numbered_checkpoints
from roto.rl.run_lock import hold_run_lock
from roto.rl.run_spec import RunSpec
from roto.rl.stop_requests import StopRequests
from roto.rl.torch_threads import single_torch_thread
from roto.rl.wandb_run import logged_wandb_project, open_wandb_run, require_wandb
from roto.sim.host_sync import deliberate_host_sync

EVAL_SEED_OFFSET = 10_000
"""Evaluation envs are seeded with seed + this, so they never replay the training envs' resets."""


class Trainer:
    """PPO on B training envs, evaluated every ``run.eval_every`` updates on separate envs.

    Args:
        spec: the run: its training envs (task, robot, obs mode, env count, seed, backend, aids),
            its agent (network, PPO, auxiliary losses, run settings) and its step budget.
        run_dir: where config, logs, evaluations and checkpoints go (created).
        tensorboard: also write TensorBoard event files (and draw the learning curve at the end).
        env_factory: builds an env from an ``EnvConfig`` (default ``RotoEnv``); tests pass a toy env
            with the same interface.
        wandb_project: also log the scalars to this Weights & Biases project (``roto.rl.wandb_run``);
            None: no W&B.
    """

    def __init__(
        self,
        spec: RunSpec,
        run_dir: str | pathlib.Path,
        tensorboard: bool = True,
        env_factory: Callable[[EnvConfig], BatchedEnv] = RotoEnv,
        wandb_project: str | None = None,
    ) -> None:
        if wandb_project is not None:
            require_wandb()
        self.spec, self.agent = spec, spec.agent
        self.run_dir = pathlib.Path(run_dir)
        extra = extra_groups(spec.agent, spec.env.obs_mode)  # checks the groups before anything is built
        created = first_missing(self.run_dir)
        (self.run_dir / CHECKPOINT_DIR).mkdir(parents=True, exist_ok=True)
        self._lock = hold_run_lock(self.run_dir)  # held from here until train() returns
        try:
            self._build(env_factory, extra)
        except BaseException:  # a refused env (too many envs, a bad file): leave no half-made run behind
            if self._lock is not None:
                self._lock.close()
            if created is not None:
                shutil.rmtree(created, ignore_errors=True)
            raise
        self.tensorboard = tensorboard
        self.wandb_project = wandb_project
        write_run_config(self.run_dir, spec)

    def _build(self, env_factory: Callable[[EnvConfig], BatchedEnv], extra: tuple[str, ...]) -> None:
        """The envs, the evaluator, the model and the learner; the counters at zero."""
        spec, agent = self.spec, self.agent
        self.env = env_factory(spec.env_config(extra_groups=extra))
        self.device = self.env.device  # the policy learns where the envs simulate
        num_eval = agent.run.num_eval_envs_gpu if self.device.type == "cuda" else agent.run.num_eval_envs
        eval_seed = spec.env.seed + EVAL_SEED_OFFSET
        self.evaluator = PolicyEvaluator(
            env_factory(for_path_metrics(spec.eval_env_config(num_eval, eval_seed))), eval_seed, self.run_dir
        )
        torch.manual_seed(spec.env.seed)
        sizes = stacked_sizes(self.env)
        self.model = build_model(sizes, self.env.num_actions, agent, spec.env.obs_mode).to(self.device)
        if agent.network.start_at_hold:
            self.model.start_mean_at(self.env.hold_action()[0].to(self.device))
        self.alg = build_learner(
            self.model, sizes, self.env.num_actions, spec.env.num_envs, agent, spec.env.seed, spec.env.touch
        )
        self.episodes = EpisodeStats(self.env.task.metric_names, self.device)
        self.update = 0
        self.env_steps = 0
        self.best_eval = (-math.inf, -math.inf)
        """(selection metric, return) of the evaluation ``best.pt`` holds (``best_eval_key``)."""
        self.train_seconds = 0.0  # rollouts + updates so far, summed over resumes (not evaluation or I/O)
        self.last_eval: dict[str, float] = {}
        self.obs: dict[str, torch.Tensor] | None = None

    @property
    def steps_per_update(self) -> int:
        """Env steps collected per PPO update (rollouts x num_envs)."""
        return self.agent.ppo.rollouts * self.spec.env.num_envs

    @property
    def total_updates(self) -> int:
        """Updates needed for the step budget (at least one)."""
        return max(1, math.ceil(self.spec.steps / self.steps_per_update))

    @property
    def finished(self) -> bool:
        """Whether the run has made its ``total_updates`` (``train`` has nothing left to do)."""
        return self.update >= self.total_updates

    # ------------------------------------------------------------------------ training

    def train(
        self, progress: bool = True, on_update: Callable[[Trainer, dict[str, float]], None] | None = None
    ) -> dict[str, float]:
        """Train until the step budget; returns the last evaluation's summary ({} if none ran).

        ``on_update(trainer, scalars)`` runs after each update is logged and checkpointed (a sweep
        reports evaluations and stops diverged or pruned trials from it by raising).
        """
        if self._lock is None:
            self._lock = hold_run_lock(self.run_dir)
        if self.obs is None:
            self.obs, _ = self.env.reset(seed=self.spec.env.seed)
        logger = self._open_logger()
        env = self.spec.env
        bar = tqdm(
            total=self.total_updates * self.steps_per_update,
            initial=self.env_steps,
            disable=not progress,
            unit="step",
            desc=f"{env.task}/{env.robot}/{env.obs_mode}",
        )
        try:
            with StopRequests() as stop:
                while not self.finished:
                    t_start = time.perf_counter()
                    with single_torch_thread(self.device):
                        scalars = self._collect_rollout()
                    t_update = time.perf_counter()
                    self.alg.compute_returns(self.obs)
                    scalars.update(self.alg.update())
                    t_end = time.perf_counter()
                    self.update += 1
                    self.env_steps += self.steps_per_update
                    self.train_seconds += t_end - t_start
                    scalars.update(
                        {
                            "perf/update_s": t_end - t_update,
                            "perf/train_wall_s": self.train_seconds,
                            "perf/steps_per_s": self.steps_per_update / (t_end - t_start),
                        }
                    )
                    scalars.update(self.episodes.read())
                    if self.update % self.agent.run.eval_every == 0 or self.update == self.total_updates:
                        scalars.update(self._evaluate())
                    logger.log(scalars, self.env_steps, self.update)
                    self._checkpoint()
                    bar.update(self.steps_per_update)
                    bar.set_postfix(self._postfix(scalars))
                    if on_update is not None:
                        on_update(self, scalars)
                    if stop.requested and not self.finished:
                        self._stop_after_update(stop.signal_name)
        finally:
            bar.close()
            logger.close()
            if self._lock is not None:  # the run is free for a resume once training stops
                self._lock.close()
                self._lock = None
        return dict(self.last_eval)

    def _stop_after_update(self, signal_name: str | None) -> None:
        """A stop asked for by a signal (``roto.rl.stop_requests``): checkpoint this update, then stop."""
        if self.update % self.agent.run.checkpoint_every != 0:  # else ``_checkpoint`` has just written it
            self.save(checkpoint_path(self.run_dir, "latest"))
        raise KeyboardInterrupt(f"{signal_name}: stopped after update {self.update}, which latest.pt holds")

    def _open_logger(self) -> ScalarLogger:
        """The run's CSV, with TensorBoard and the W&B run as asked."""
        wandb_run = None
        if self.wandb_project is not None:
            wandb_run = open_wandb_run(self.run_dir, self.wandb_project, run_config(self.spec))
        return ScalarLogger(self.run_dir, self.tensorboard, wandb_run, update=self.update, env_steps=self.env_steps)

    def _collect_rollout(self) -> dict[str, float]:
        """``rollouts`` steps of every training env into the learner's buffer; timings."""
        t_inference = t_sim = 0.0
        for _ in range(self.agent.ppo.rollouts):
            t0 = time.perf_counter()
            action = self.alg.act(self.obs)
            t1 = time.perf_counter()
            self.obs, reward, terminated, truncated, info = self.env.step(action)
            t2 = time.perf_counter()
            self.alg.process_step(reward, terminated, truncated, info)
            self.episodes.add(info)
            t_inference += t1 - t0
            t_sim += t2 - t1
        scalars = {"perf/inference_s": t_inference, "perf/simulation_s": t_sim}
        with deliberate_host_sync(self.device):  # the training aids' state (if any), read once per update
            scalars.update({name: float(value) for name, value in self.env.aid_metrics().items()})
        return scalars

    def _evaluate(self) -> dict[str, float]:
        """Evaluate the current weights; ``best.pt`` gets them when they beat every earlier evaluation."""
        record = self.evaluator.evaluate(
            self.model, update=self.update, env_steps=self.env_steps, train_wall_s=self.train_seconds
        )
        summary = {key: value for key, value in record.items() if key.endswith(("_mean", "_std"))}
        self.last_eval = {f"eval/{key}": value for key, value in summary.items()}
        key = best_eval_key(record, self.env.task.selection_metric)
        if key > self.best_eval:
            self.best_eval = key
            self.save(checkpoint_path(self.run_dir, "best"), policy_only=True)
        return {**self.last_eval, "perf/eval_s": record["eval_s"]}

    def _checkpoint(self) -> None:
        every = self.agent.run.checkpoint_every
        if self.update % every == 0 or self.update == self.total_updates:
            self.save(checkpoint_path(self.run_dir, "latest"))
        keep = self.agent.run.keep_checkpoints
        if self.update % every == 0:
            if keep > 0:
                self.save(checkpoint_path(self.run_dir, f"agent_{self.update}"), policy_only=True)
            for old in numbered_checkpoints(self.run_dir)[: -keep or None]:  # keep 0: every one goes
                old.unlink()

    def _postfix(self, scalars: dict[str, float]) -> dict[str, str]:
        postfix = {"steps/s": f"{scalars['perf/steps_per_s']:.0f}"}
        if self.last_eval:
            postfix["eval return"] = f"{self.last_eval['eval/return_mean']:.1f}"
            selection = self.env.task.selection_metric
            for m in (selection,) if selection else ():
                postfix[f"eval {m}"] = f"{self.last_eval[f'eval/{m}_mean']:.2f}"
            for m in self.env.task.metric_names:
                postfix[f"eval {m}"] = f"{self.last_eval[f'eval/{m}_mean']:.2f}"
        return postfix

    # ---------------------------------------------------------------------- checkpoints

    def state_dict(self) -> dict[str, Any]:
        """Everything needed to continue bit-identically (plain data: see ``roto.rl.checkpoints``)."""
        return {
            **self.policy_state(),
            "ppo": self.alg.state_dict(),
            "torch_rng": torch.get_rng_state(),
            "env": self.env.state_dict(),
            "obs": self.obs,
            "train_seconds": self.train_seconds,
        }

    def policy_state(self) -> dict[str, Any]:
        """The policy and what loading it needs (``POLICY_KEYS``): no optimiser, env or RNG state
        (a third of ``state_dict``'s size, and nothing copied from the envs)."""
        return {
            **format_stamp("checkpoint"),
            "model": self.model.state_dict(),
            "spec": self.spec.to_dict(),
            "obs_sizes": stacked_sizes(self.env),
            "num_actions": self.env.num_actions,
            "update": self.update,
            "env_steps": self.env_steps,
            "best_eval": list(self.best_eval),
            "last_eval": self.last_eval,
        }

    def close(self) -> None:
        """Release both env sets' backends (the training envs' and the evaluation envs')."""
        self.env.close()
        self.evaluator.env.close()

    def __enter__(self) -> Trainer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def save(self, path: pathlib.Path, policy_only: bool = False) -> None:
        """Write a checkpoint atomically: everything to resume from, or with ``policy_only`` the
        policy alone (``best.pt`` and the numbered copies)."""
        save_checkpoint(self.policy_state() if policy_only else self.state_dict(), path)

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore a checkpoint written by ``save``; evaluations recorded after it are dropped."""
        self.model.load_state_dict(state["model"])
        self.alg.load_state_dict(state["ppo"])
        torch.set_rng_state(state["torch_rng"].cpu())
        self.env.load_state_dict(state["env"])
        self.obs = state["obs"]
        self.update, self.env_steps = int(state["update"]), int(state["env_steps"])
        self.best_eval = load_best_eval(state, self.env.task.selection_metric)
        self.train_seconds = float(state["train_seconds"])
        self.last_eval = dict(state["last_eval"])
        self.evaluator.drop_after(self.update)

    @classmethod
    def open(
        cls,
        run_dir: str | pathlib.Path,
        spec: RunSpec | None = None,
        *,
        steps: int | None = None,
        tensorboard: bool = True,
        env_factory: Callable[[EnvConfig], BatchedEnv] = RotoEnv,
        wandb_project: str | None = None,
    ) -> Trainer:
        """The run in ``run_dir``: continued from its latest checkpoint when it has one, else created
        from ``spec``.

        With a spec, a run that exists must train what the spec says (only its budget may grow,
        to ``spec.steps``, and it continues on ``spec.env.threads``); without one, ``steps`` is a
        new budget for the run (None: unchanged).

        Raises:
            ValueError listing the differences when an existing run was configured otherwise;
            FileNotFoundError (via ``resume``) when there is neither a checkpoint nor a spec.
        """
        run_dir = pathlib.Path(run_dir)
        if spec is None or RunDir(run_dir).has_checkpoint():
            if spec is not None:
                differ = spec.differences(RunDir(run_dir).config())
                if differ:
                    raise ValueError(
                        f"run {str(run_dir)!r} exists with other settings (given, stored): {differ}; continue it as "
                        "it is, or start another run directory"
                    )
                steps = spec.steps
            threads = spec.env.threads if spec is not None else None
            return cls.resume(run_dir, steps, tensorboard, env_factory, wandb_project, threads=threads)
        trainer = cls(spec, run_dir, tensorboard, env_factory, wandb_project)
        trainer.evaluator.drop_after(0)  # a run that died before its first checkpoint starts over, records too
        return trainer

    @classmethod
    def resume(
        cls,
        run_dir: str | pathlib.Path,
        total_steps: int | None = None,
        tensorboard: bool = True,
        env_factory: Callable[[EnvConfig], BatchedEnv] = RotoEnv,
        wandb_project: str | None = None,
        *,
        threads: int | None = None,
    ) -> Trainer:
        """A trainer continuing ``run_dir`` from its latest checkpoint (optionally with a new step
        budget, and on ``threads`` C threads instead of the run's own).

        A run that logged to W&B continues its W&B run; ``wandb_project`` adds W&B to one that did not.
        """
        run_dir = pathlib.Path(run_dir)
        spec = read_run_config(run_dir)
        checkpoint = checkpoint_path(run_dir, "latest")
        if not checkpoint.is_file():
            raise FileNotFoundError(f"no checkpoint to resume from: {str(checkpoint)!r} does not exist")
        state = load_checkpoint(checkpoint)  # read before anything is built or written
        if "ppo" not in state:
            raise ValueError(
                f"{str(checkpoint)!r} holds a policy only (as best.pt and the numbered copies do), not the "
                "optimiser and env state a resume needs"
            )
        if total_steps is not None and total_steps < int(state["env_steps"]):
            raise ValueError(
                f"step budget {total_steps} is below the {int(state['env_steps'])} env steps {str(run_dir)!r} has "
                "already done; give a budget at least that large"
            )
        if total_steps is not None:
            spec = spec.with_steps(total_steps)
        if threads is not None:
            spec = dataclasses.replace(spec, env=spec.env_config(threads=threads))
        wandb_project = logged_wandb_project(run_dir) or wandb_project
        trainer = cls(spec, run_dir, tensorboard=tensorboard, env_factory=env_factory, wandb_project=wandb_project)
        trainer.load_state_dict(state if trainer.device.type == "cpu" else load_checkpoint(checkpoint, trainer.device))
        return trainer
