"""roto's PPO agent: networks, normalisers, GAE, losses, storage, the update and the training loop."""
