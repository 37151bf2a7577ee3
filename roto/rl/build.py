"""From configs to modules: which observation groups each network reads, the model, the learner."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import torch

from roto.envs.observations import OBS_GROUPS, OBS_MODES
from roto.rl.config import AgentConfig
from roto.rl.networks import ActorCritic
from roto.rl.ppo import PPO
from roto.rl.ssl import build_aux_losses
from roto.rl.ssl.configs import ReconstructionConfig
from roto.rl.storage import RolloutBuffer


@dataclass(frozen=True)
class Groups:
    """The observation groups of a run: the policy's, the critic's and every group the env must return."""

    actor: tuple[str, ...]
    critic: tuple[str, ...]
    needed: tuple[str, ...]
    """actor ∪ critic ∪ auxiliary targets, in the env's group order."""


def resolve_groups(agent: AgentConfig, obs_mode: str) -> Groups:
    """Route groups as the agent config asks, within what ``obs_mode`` lets the policy see.

    The actor reads the obs mode's groups unless ``network.actor`` names a subset of them; it never
    reads a group outside the obs mode (a blind policy never sees privileged state). The critic
    reads the actor's groups unless ``network.critic`` names others; auxiliary targets may name any
    group. Every group needed beyond the obs mode's is returned by the env as an extra group.
    """
    mode = OBS_MODES[obs_mode]
    actor = agent.network.actor or mode
    outside = [g for g in actor if g not in mode]
    if outside:
        raise ValueError(
            f"network.actor reads {outside}, which obs mode {obs_mode!r} does not give the policy; "
            f"valid groups for this obs mode: {list(mode)}"
        )
    critic = agent.network.critic or actor
    targets = [
        g for loss in agent.ssl.enabled().values() if isinstance(loss, ReconstructionConfig) for g in loss.targets
    ]
    wanted = {*actor, *critic, *targets}
    return Groups(actor=tuple(actor), critic=tuple(critic), needed=tuple(g for g in OBS_GROUPS if g in wanted))


def extra_groups(agent: AgentConfig, obs_mode: str) -> tuple[str, ...]:
    """Groups the env must return beyond the obs mode's (``EnvConfig.extra_groups``)."""
    return tuple(g for g in resolve_groups(agent, obs_mode).needed if g not in OBS_MODES[obs_mode])


def build_model(sizes: Mapping[str, int], num_actions: int, agent: AgentConfig, obs_mode: str) -> ActorCritic:
    """The actor-critic for stacked group sizes ``sizes`` ({group: k·frame size})."""
    groups = resolve_groups(agent, obs_mode)
    net = agent.network
    return ActorCritic(
        sizes,
        num_actions,
        actor_groups=groups.actor,
        critic_groups=groups.critic,
        encoder=net.encoder,
        policy_head=net.policy_head,
        value_head=net.value_head,
        init_log_std=net.init_log_std,
        max_log_std=net.max_log_std,
        project_log_std=net.project_log_std,
        obs_normalization=net.obs_normalization,
    )


def build_learner(
    model: ActorCritic,
    sizes: Mapping[str, int],
    num_actions: int,
    num_envs: int,
    agent: AgentConfig,
    seed: int,
    touch: str,
) -> PPO:
    """PPO with its rollout buffer (every group in ``sizes``), generator and auxiliary losses
    (``touch``: the env's touch signal, for a reconstruction of the tactile group)."""
    device = next(model.parameters()).device
    buffer = RolloutBuffer(agent.ppo.rollouts, num_envs, sizes, num_actions, device)
    generator = torch.Generator(device=device).manual_seed(seed)
    aux = build_aux_losses(agent.ssl, model, sizes, num_actions, agent.ppo.rollouts * num_envs, touch)
    return PPO(model, agent.ppo, buffer, generator, aux)


def stacked_sizes(env: object) -> dict[str, int]:
    """{group: stacked size} of every group ``env`` returns (frame size times the frame stack)."""
    return {group: size * env.config.frame_stack for group, size in env.frame_sizes.items()}


def check_policy_fits(model: ActorCritic, env: object) -> None:
    """Refuse to run ``model`` on ``env`` when the groups it reads or its actions have other sizes
    (a checkpoint whose task, hand or obs mode labels were changed, or belong to other weights).

    Raises:
        ValueError naming both sets of sizes and the env's task, robot and obs mode.
    """
    sizes = stacked_sizes(env)
    given = {group: sizes.get(group) for group in model.actor_sizes}
    if given != model.actor_sizes or env.num_actions != model.num_actions:
        config = env.config
        raise ValueError(
            f"the checkpoint's policy reads {model.actor_sizes} and acts on {model.num_actions} joints, but "
            f"{config.task} on {config.robot} ({config.obs_mode}), which the checkpoint names, gives {given} and "
            f"{env.num_actions}: its labels do not belong to its weights"
        )
