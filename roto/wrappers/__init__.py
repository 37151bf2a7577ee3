"""Adapters that hand roto's batched environments to Gymnasium (its registered ids) and to other learning
libraries (optional extras)."""
