"""Forward dynamics trained on its own memory of sequences (roto's best blind Baoding agent).

The loss is ``ForwardDynamics``'s; only where its sequences come from differs. Every rollout's
valid windows, including those that start in the previous rollout's last steps, enter a FIFO of
``capacity`` windows (default rollouts x num_envs); each update trains on everything the FIFO
holds, shuffled once into one batch per PPO minibatch.
"""

from __future__ import annotations

from typing import Any

from roto.rl.networks import ActorCritic
from roto.rl.ssl.configs import ForwardDynamicsMemoryConfig
from roto.rl.ssl.forward_dynamics import ForwardDynamics
from roto.rl.ssl.sequences import SequenceMemory
from roto.rl.storage import RolloutBuffer


class ForwardDynamicsMemory(ForwardDynamics):
    """``ForwardDynamics`` over a ``SequenceMemory`` fed with every rollout.

    Args:
        name, config, model, num_actions: as ``ForwardDynamics``.
        default_capacity: windows held when ``config.capacity`` is 0 (rollouts x num_envs).
    """

    def __init__(
        self,
        name: str,
        config: ForwardDynamicsMemoryConfig,
        model: ActorCritic,
        num_actions: int,
        default_capacity: int,
    ) -> None:
        super().__init__(name, config, model, num_actions)
        self.memory = SequenceMemory(config.capacity or default_capacity, config.seq_length)

    def windows(self, buffer: RolloutBuffer) -> dict:
        """Feed the rollout into the memory; train on everything it holds."""
        self.memory.add_rollout(buffer.obs, buffer.actions, buffer.dones)
        return self.memory.contents()

    def state_dict(self) -> dict[str, Any]:
        """As ``ForwardDynamics``, plus the memory."""
        return {**super().state_dict(), "memory": self.memory.state_dict()}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore ``state_dict``'s output."""
        super().load_state_dict(state)
        self.memory.load_state_dict(state["memory"])
