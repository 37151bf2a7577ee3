"""PPO's minibatch step recorded once into a CUDA graph and replayed for every minibatch.

On a GPU, roto's update (17 epochs x 8 minibatches of 16 384 samples at 8192 envs) costs far more
than its arithmetic: each minibatch step launches some hundreds of small kernels (forward, loss
terms, backward, gradient clip, Adam), and the host's time to issue them, not the device's time to
run them, sets the pace (docs/backends.md). A CUDA graph issues the whole step with one launch.

``GraphedMinibatchStep`` wraps a step function. On its first call it copies the minibatch into
tensors of its own, runs the step a few times on a side stream (CUDA needs its kernels loaded and
the optimiser's state allocated before a capture), undoes those warm-up steps on the weights and
the optimiser state, and records one step. Every call then copies the minibatch into the recorded
inputs and replays the graph; the returned metrics are the recorded outputs, overwritten by the
next call, so read them (or add them up) before calling again.

What the step may do: the same kernels on the same shapes every call, no host reads (no ``.item()``,
no branch on a tensor's value), no new optimiser state after the warm-up, and a learning rate that
is either fixed or a device tensor changed in place (Adam with ``capturable=True``). roto's PPO
step without auxiliary losses is such a step (``roto.rl.ppo``; ``ppo.cuda_graph``).
"""

from __future__ import annotations

from collections.abc import Callable

import torch
from torch import nn

from roto.rl.graphed_call import GraphedCall, Metrics, clone_tree


def _optimizer_tensors(optimizer: torch.optim.Optimizer) -> list[torch.Tensor]:
    """Every tensor of the optimiser's per-parameter state (Adam: step, exp_avg, exp_avg_sq)."""
    return [value for state in optimizer.state.values() for value in state.values() if torch.is_tensor(value)]


class GraphedMinibatchStep(GraphedCall):
    """``step(batch) -> metrics``, replayed from a CUDA graph.

    Args:
        step: one training step on a minibatch (a nested dict of tensors of fixed shapes), returning
            a dict of scalar tensors; it runs backward and the optimiser's step itself.
        model: the module ``step`` trains; its parameters are restored after the warm-up.
        optimizer: the optimiser ``step`` uses (``capturable=True``); its state is restored after the
            warm-up (zeros where it had none: a fresh Adam's state).
    """

    def __init__(self, step: Callable[[dict], Metrics], model: nn.Module, optimizer: torch.optim.Optimizer) -> None:
        super().__init__(step)
        self._model, self._optimizer = model, optimizer

    def _capture(self, batch: dict) -> None:
        """Warm up on a side stream, undo the warm-up, record one step."""
        self._inputs = clone_tree(batch)
        params = [p.detach() for p in self._model.parameters()]
        saved_params = [p.clone() for p in params]
        had_state = bool(self._optimizer.state)
        saved_state = [t.clone() for t in _optimizer_tensors(self._optimizer)]
        self._warm_up()
        with torch.no_grad():
            for param, saved in zip(params, saved_params, strict=True):
                param.copy_(saved)
            state = _optimizer_tensors(self._optimizer)
            if had_state:
                for tensor, saved in zip(state, saved_state, strict=True):
                    tensor.copy_(saved)
            else:
                for tensor in state:
                    tensor.zero_()
        self._optimizer.zero_grad(set_to_none=True)  # backward allocates the gradients inside the graph
        self._record()
