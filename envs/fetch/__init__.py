"""Fetch-style manipulation tasks (Reach, Push, Slide, PickAndPlace) as pure MJX functions."""
