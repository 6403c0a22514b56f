"""Helpers for road-user experiments, importable in transceiver functions."""
