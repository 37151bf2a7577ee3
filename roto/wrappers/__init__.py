"""Adapters that hand roto's batched environments to other learning libraries (optional extras)."""
