"""Shared test scenes, harnesses and comparisons (imported by tests; never a test module)."""
