"""``roto train``: a run of roto's PPO from a task, a hand and an agent config, or continued with
``--resume`` from its latest checkpoint."""

from __future__ import annotations

import argparse
import json
import sys

from roto.cli_args import add_env_args, add_touch_arg, env_flags, options_given
from roto.cli_errors import check_output_path
from roto.rl.config_help import HelpConfigAction
from roto.value_checks import check_count


def lead_first(evaluation: dict[str, float], lead: str | None) -> dict[str, float]:
    """An evaluation's ``eval/<name>`` scalars without the prefix, those of the task's ``lead``
    measure (Baoding: round rotations) first."""

    def later(item: tuple[str, float]) -> bool:
        return lead is None or not item[0].startswith(f"eval/{lead}_")

    return {key.removeprefix("eval/"): value for key, value in sorted(evaluation.items(), key=later)}


def _cmd_train(args: argparse.Namespace) -> int:
    import pathlib
    import time

    import torch

    from roto.eval.plots import plot_learning_curve
    from roto.rl.run_config import CONFIG_NAME
    from roto.rl.run_spec import DEFAULT_STEPS, build_run_spec
    from roto.rl.runner import Trainer

    check_count("--torch_threads", args.torch_threads, 1)
    torch.set_num_threads(args.torch_threads)
    wandb_project = args.wandb_project if args.logger == "wandb" else None
    if args.resume:
        _refuse_ignored_resume_flags(args)
        threads = args.threads if "threads" in _train_options_given(args) else None
        trainer = Trainer.resume(args.resume, args.steps, wandb_project=wandb_project, threads=threads)
    else:
        # the env flags are shorthand for env.* overrides, which win over them; all checked before anything is written
        steps = args.steps if args.steps is not None else DEFAULT_STEPS
        spec = build_run_spec(args.task, args.robot, args.obs, args.agent_cfg, args.overrides, steps, **env_flags(args))
        run_dir = args.run_dir or pathlib.Path("runs") / (
            f"{spec.env.task}_{spec.env.robot}_{args.obs}" + f"/{time.strftime('%Y%m%d-%H%M%S')}_seed{spec.env.seed}"
        )
        check_output_path(run_dir, "--run_dir", kind="dir")
        if (pathlib.Path(run_dir) / CONFIG_NAME).exists():
            raise ValueError(
                f"--run_dir {str(run_dir)!r} already holds a run; continue it with --resume {str(run_dir)!r}, "
                "or choose another directory"
            )
        trainer = Trainer.open(run_dir, spec, wandb_project=wandb_project)
    print(f"run directory: {trainer.run_dir}", file=sys.stderr)
    try:
        last = trainer.train(progress=not args.no_progress)
    except KeyboardInterrupt as stop:  # Ctrl-C, kill or a time limit's signal: a stop, not an error
        print(
            f"roto train: interrupted at update {trainer.update} ({str(stop) or 'at once'}); `roto train --resume "
            f"{trainer.run_dir}` continues from its latest checkpoint",
            file=sys.stderr,
        )
        return 130
    plot_learning_curve(trainer.run_dir, selection_metric=trainer.env.task.selection_metric)
    summary = {"run_dir": str(trainer.run_dir), "env_steps": trainer.env_steps, "updates": trainer.update}
    summary.update(lead_first(last, trainer.env.task.selection_metric))
    summary["spec"] = trainer.spec.to_dict()
    print(json.dumps(summary))
    return 0


RESUME_KEEPS = ("resume", "steps", "threads", "torch_threads", "no_progress", "logger", "wandb_project", "headless")
"""What ``roto train --resume`` takes from the command line: the budget and how to run; the rest is the run's."""


def _train_options_given(args: argparse.Namespace) -> set[str]:
    """The destinations of the ``roto train`` options the command line gave itself."""
    probe = argparse.ArgumentParser(prog="roto").add_subparsers()
    add_train_parser(probe)
    argv = args.argv[args.argv.index("train") + 1 :]
    return options_given(probe.choices["train"], argv)


def _refuse_ignored_resume_flags(args: argparse.Namespace) -> None:
    """Refuse, naming them, the flags and overrides that ``--resume`` would ignore."""
    ignored = sorted(_train_options_given(args) - set(RESUME_KEEPS))
    if not ignored:
        return
    named = [f"--{dest}" for dest in ignored if dest != "overrides"]
    named += [f"the overrides {args.overrides}"] if "overrides" in ignored else []
    raise ValueError(
        f"--resume continues a run as it was configured; {', '.join(named)} would be ignored: drop "
        f"{'it' if len(named) == 1 else 'them'}, or start a new run with --run_dir (--resume keeps only "
        "--steps, --threads, --torch_threads, --no_progress, --logger and --wandb_project)"
    )


def add_train_parser(sub: argparse._SubParsersAction) -> None:
    p_train = sub.add_parser(
        "train", help="train roto's PPO agent, optionally with auxiliary losses (progress bar, logs, checkpoints)"
    )
    add_env_args(p_train, num_envs=64)
    add_touch_arg(p_train)
    p_train.add_argument(
        "--obs", "--obs_mode", "--obs-mode", dest="obs", default="blind", help="blind, state or proprio"
    )
    p_train.add_argument(
        "--steps", type=int, default=None, help="env-step budget (default 1e6; with --resume: unchanged)"
    )
    p_train.add_argument(
        "--agent_cfg",
        "--agent-cfg",
        dest="agent_cfg",
        default=None,
        help="agent YAML file, or a packaged config's name (e.g. bounce_forward_dynamics, "
        "baoding_forward_dynamics_memory, bounce_privileged_critic; default: the task's PPO)",
    )
    p_train.add_argument(
        "--run_dir", "--run-dir", dest="run_dir", default=None, help="default: runs/<task>_<robot>_<obs>/<time>"
    )
    p_train.add_argument("--resume", default=None, metavar="RUN_DIR", help="continue a run from its latest checkpoint")
    p_train.add_argument(
        "--torch_threads",
        "--torch-threads",
        dest="torch_threads",
        type=int,
        default=1,
        help="torch CPU threads for the PPO update; rollouts always use one (default 1)",
    )
    p_train.add_argument(
        "--no_progress",
        "--no-progress",
        dest="no_progress",
        action="store_true",
        help="no progress bar (for logs; scalars and evaluations still go to the run directory)",
    )
    p_train.add_argument("--help-config", "--help_config", action=HelpConfigAction)
    p_train.add_argument(
        "--logger",
        choices=("tensorboard", "wandb"),
        default="tensorboard",
        help="where the scalars go besides scalars.csv: tensorboard (default), or wandb: Weights & Biases as well "
        "as TensorBoard (pip install -e '.[wandb]'; WANDB_MODE=offline needs no account); a resumed W&B run "
        "keeps logging to W&B",
    )
    p_train.add_argument(
        "--wandb_project", "--wandb-project", dest="wandb_project", default="roto", help="W&B project (default: roto)"
    )
    p_train.add_argument(
        "overrides",
        nargs="*",
        metavar="section.key=value",
        help="agent config overrides (ppo.lr=1e-4) and env overrides (env.num_envs=64)",
    )
    p_train.set_defaults(func=_cmd_train)
