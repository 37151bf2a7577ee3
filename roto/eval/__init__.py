"""Evaluation of trained policies and policy videos."""
