"""``roto`` command line: ``roto train``, ``eval``, ``play``, ``render``, ``list``, ``bench``, ``demo``, ``sweep``,
``olympiad``, ``results``."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence

from roto.cli_args import add_checkpoint_arg, add_env_args, add_touch_arg, options_given
from roto.cli_demo import add_demo_parser
from roto.cli_errors import check_output_path, error_exit, make_parents, quiet_on_closed_stdout
from roto.eval.protocol import EVAL_EPISODES, EVAL_SEED
from roto.olympiad.command import add_olympiad_parsers
from roto.rl.config_help import HelpConfigAction
from roto.rl.stop_requests import interrupt_on_sigterm
from roto.sweep.command import add_sweep_parser
from roto.value_checks import check_count


def _cmd_list(args: argparse.Namespace) -> int:
    import roto
    from roto.registry import gym_id
    from roto.robots import ROBOTS, get_robot
    from roto.sim.scene import hand_taxels

    header = f"{'task':<9} {'robot':<12} {'gymnasium id':<30} {'actions':>7} {'frame (blind)':>13} {'stacked':>8}"
    print(f"{header} {'taxels':>6} {'frame (taxels)':>14}")
    taxels = {robot: len(hand_taxels(get_robot(robot))) for robot in ROBOTS}
    for task, robot in roto.list_envs():
        env = roto.make(task, robot=robot, num_envs=1)
        frame = sum(env.frame_sizes.values())
        stacked = frame * env.config.frame_stack
        row = f"{task:<9} {robot:<12} {gym_id(task, robot):<30} {env.num_actions:>7} {frame:>13} {stacked:>8}"
        print(f"{row} {taxels[robot]:>6} {frame + taxels[robot]:>14}")
        env.close()
    return 0


def _cmd_bench(args: argparse.Namespace) -> int:
    from roto.bench import run_bench

    result = run_bench(
        task=args.task,
        robot=args.robot,
        num_envs=args.num_envs,
        threads=args.threads,
        steps=args.steps,
        obs_mode=args.obs_mode,
        seed=args.seed,
        backend=args.backend,
        device=args.device,
        touch=args.touch,
    )
    if args.json:
        print(json.dumps(result))
    else:
        for key, value in result.items():
            print(f"{key:>24}: {value}")
    return 0


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
        flags = dict(
            num_envs=args.num_envs,
            seed=args.seed,
            backend=args.backend,
            device=args.device,
            threads=args.threads,
            touch=args.touch,
        )
        steps = args.steps if args.steps is not None else DEFAULT_STEPS
        spec = build_run_spec(args.task, args.robot, args.obs, args.agent_cfg, args.overrides, steps, **flags)
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
    _add_train_parser(probe)
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


def _cmd_eval(args: argparse.Namespace) -> int:
    import pathlib

    from roto.eval.evaluate import evaluate
    from roto.result_files import write_text_atomic
    from roto.rl.run_dir import load_policy
    from roto.tasks import get_task

    out = pathlib.Path(args.out) if args.out else pathlib.Path(args.checkpoint).with_suffix(".eval.json")
    check_output_path(out, "--out", example="eval.json")  # before the evaluation, which would be lost
    model, spec = load_policy(args.checkpoint)
    result = evaluate(model, spec, episodes=args.episodes, seed=args.seed)
    env = spec.env
    result = {
        "checkpoint": str(args.checkpoint),
        **{"task": env.task, "task_version": get_task(env.task).version, "robot": env.robot, "obs": env.obs_mode},
        **{"touch": env.touch, "train_seed": env.seed, **result},
    }
    write_text_atomic(make_parents(out), json.dumps(result, indent=1))
    print(json.dumps({k: v for k, v in result.items() if k != "per_episode"}))
    print(f"wrote {out}", file=sys.stderr)
    return 0


def _cmd_play(args: argparse.Namespace) -> int:
    from roto.eval.video import record_video
    from roto.rl.run_dir import load_policy

    check_output_path(args.video, "--video", example="play.mp4")  # missing folders are made when it is written
    model, spec = load_policy(args.checkpoint)
    result = record_video(model, spec, args.video, steps=args.video_length, seed=args.seed)
    print(json.dumps({"video": str(args.video), **result}))
    return 0


def _cmd_render(args: argparse.Namespace) -> int:
    from roto.eval.video import render_scene

    check_output_path(args.out, "--out", example="scene.png")  # missing folders are made when it is written
    path = render_scene(
        args.task, args.robot, args.out, settle_steps=args.settle_steps, seed=args.seed, touch=args.touch
    )
    print(json.dumps({"task": args.task, "robot": args.robot, "image": str(path)}))
    return 0


def _add_train_parser(sub: argparse._SubParsersAction) -> None:
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


def _add_eval_parser(sub: argparse._SubParsersAction) -> None:
    p_eval = sub.add_parser("eval", help="evaluate a checkpoint over full episodes (deterministic policy)")
    add_checkpoint_arg(p_eval)
    p_eval.add_argument(
        "--episodes",
        type=int,
        default=EVAL_EPISODES,
        help=f"full episodes, one per env (default: {EVAL_EPISODES}, the benchmark's)",
    )
    p_eval.add_argument(
        "--seed",
        type=int,
        default=EVAL_SEED,
        help=f"seed of the first batch of starts (default: {EVAL_SEED}, the benchmark's, apart from training seeds)",
    )
    p_eval.add_argument(
        "--out", default=None, help="JSON path (default: next to the checkpoint; missing folders are created)"
    )
    p_eval.set_defaults(func=_cmd_eval)


def _add_play_parser(sub: argparse._SubParsersAction) -> None:
    p_play = sub.add_parser("play", help="render a checkpoint's policy offscreen into an mp4")
    add_checkpoint_arg(p_play)
    p_play.add_argument(
        "--video", default="videos/play.mp4", help="mp4 path (default: videos/play.mp4; missing folders are created)"
    )
    p_play.add_argument(
        "--video_length",
        "--video-length",
        dest="video_length",
        type=int,
        default=600,
        help="control steps to record (default: 600, one 10 s episode)",
    )
    p_play.add_argument("--seed", type=int, default=0, help="seed of the episode's start (default: 0)")
    p_play.add_argument("--headless", action="store_true", help="accepted for Isaac Lab compatibility; always headless")
    p_play.set_defaults(func=_cmd_play)


def _add_render_parser(sub: argparse._SubParsersAction) -> None:
    p_render = sub.add_parser("render", help="a PNG of a hand in a task scene (offscreen, no display needed)")
    p_render.add_argument("--task", default="bounce")
    p_render.add_argument("--robot", default="shadow")
    p_render.add_argument(
        "--out", default="scene.png", help="PNG or JPEG path (default: scene.png; missing folders are created)"
    )
    add_touch_arg(p_render)
    p_render.add_argument(
        "--settle_steps",
        "--settle-steps",
        dest="settle_steps",
        type=int,
        default=60,
        help="control steps holding the default pose before the picture (default: 60)",
    )
    p_render.add_argument("--seed", type=int, default=0)
    p_render.set_defaults(func=_cmd_render)


def _add_list_parser(sub: argparse._SubParsersAction) -> None:
    p_list = sub.add_parser("list", help="every (task, robot) pair with its observation and action sizes")
    p_list.set_defaults(func=_cmd_list)


def _add_bench_parser(sub: argparse._SubParsersAction) -> None:
    p_bench = sub.add_parser("bench", help="env throughput vs plain physics stepping of the same model")
    add_env_args(p_bench, num_envs=256)
    add_touch_arg(p_bench)
    p_bench.add_argument("--steps", type=int, default=200, help="timed control steps (default: 200)")
    p_bench.add_argument("--obs_mode", "--obs-mode", dest="obs_mode", default="blind")
    p_bench.add_argument("--json", action="store_true", help="print one JSON object")
    p_bench.set_defaults(func=_cmd_bench)


def build_parser() -> argparse.ArgumentParser:
    """The ``roto`` argument parser."""
    parser = argparse.ArgumentParser(prog="roto", description="roto: the Robot Tactile Olympiad on MuJoCo")
    parser.add_argument(
        "--debug", action="store_true", help="show the full traceback of an error instead of its one-line message"
    )
    sub = parser.add_subparsers(dest="command", required=True)
    # the order here is the order ``roto --help`` lists the subcommands in
    for add in (
        _add_train_parser,
        _add_eval_parser,
        _add_play_parser,
        _add_render_parser,
        _add_list_parser,
        _add_bench_parser,
        add_demo_parser,
        add_sweep_parser,
        add_olympiad_parsers,
    ):
        add(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``roto`` command; a closed stdout (``roto ... | head -1``) ends it quietly."""
    with quiet_on_closed_stdout():
        return _run(argv)


def _run(argv: Sequence[str] | None) -> int:
    """Parse ``argv`` and run its command inside the error boundary (``roto.cli_errors``)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    args = build_parser().parse_args(argv)
    args.argv = argv
    interrupt_on_sigterm()
    try:
        return int(args.func(args))
    except KeyboardInterrupt:  # Ctrl-C: a stop, not an error (a sweep's or Olympiad's trial is retried on the next run)
        if args.debug:
            raise
        print(f"roto {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # stdout's reader went away: for quiet_on_closed_stdout, not an error to print
        raise
    except Exception as error:
        if args.debug:
            raise
        code, kind = error_exit(error)
        if code is None:
            raise
        print(f"roto {args.command}: {kind}: {error}", file=sys.stderr)
        return code


if __name__ == "__main__":
    raise SystemExit(main())
