"""``roto`` command line: ``roto train``, ``eval``, ``play``, ``render``, ``list``, ``bench``, ``demo``, ``sweep``,
``olympiad``, ``results``."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence

from roto.cli_args import add_checkpoint_arg, add_env_args, add_touch_arg, env_flags
from roto.cli_demo import add_demo_parser
from roto.cli_errors import check_output_path, error_exit, make_parents, quiet_on_closed_stdout
from roto.cli_train import add_train_parser
from roto.eval.protocol import EVAL_EPISODES, EVAL_SEED
from roto.olympiad.command import add_olympiad_parsers
from roto.rl.stop_requests import interrupt_on_sigterm
from roto.sweep.command import add_sweep_parser


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

    result = run_bench(task=args.task, robot=args.robot, steps=args.steps, obs_mode=args.obs_mode, **env_flags(args))
    if args.json:
        print(json.dumps(result))
    else:
        for key, value in result.items():
            print(f"{key:>24}: {value}")
    return 0


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
        add_train_parser,
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
