"""Rerun recording of a plan (stub, being written)."""


def write_recording(path, scene, plan) -> None:
    raise NotImplementedError
