"""Exact bat-ball time of impact from tracked frames."""
