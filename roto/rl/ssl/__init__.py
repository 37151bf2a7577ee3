"""roto's self-supervised auxiliary losses (docs/spec.md §7): one protocol, one builder per name."""

from __future__ import annotations

from collections.abc import Mapping

from roto.rl.networks import ActorCritic
from roto.rl.ssl.configs import SSLConfig
from roto.rl.ssl.forward_dynamics import ForwardDynamics
from roto.rl.ssl.forward_dynamics_memory import ForwardDynamicsMemory
from roto.rl.ssl.protocol import AuxLoss, aux_epochs
from roto.rl.ssl.reconstruction import Reconstruction


def build_aux_losses(
    config: SSLConfig,
    model: ActorCritic,
    sizes: Mapping[str, int],
    num_actions: int,
    samples_per_rollout: int,
    touch: str,
) -> list[AuxLoss]:
    """The enabled losses of ``config``, each with its heads on the model's device and its own Adam.

    Args:
        config: the agent config's ``ssl`` section.
        model: the actor-critic whose encoder they train.
        sizes: {group: stacked size} of every group the env returns.
        num_actions: n.
        samples_per_rollout: rollouts x num_envs (the memory's default capacity).
        touch: the env's touch signal (what a reconstruction of the tactile group decodes).
    """
    builders = {
        "tactile_reconstruction": lambda name, c: Reconstruction(name, c, model, sizes, touch),
        "full_reconstruction": lambda name, c: Reconstruction(name, c, model, sizes, touch),
        "forward_dynamics": lambda name, c: ForwardDynamics(name, c, model, num_actions),
        "forward_dynamics_memory": lambda name, c: ForwardDynamicsMemory(
            name, c, model, num_actions, samples_per_rollout
        ),
    }
    return [builders[name](name, loss_config) for name, loss_config in config.enabled().items()]


__all__ = ["AuxLoss", "aux_epochs", "build_aux_losses"]
