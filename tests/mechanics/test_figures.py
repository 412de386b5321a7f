"""The figure script writes every PNG (on a coarse ray search, to stay fast)."""

from __future__ import annotations

import pytest

pytest.importorskip("matplotlib")

from mechanics.figures import FIGURES, main  # noqa: E402


def test_every_figure_is_written(tmp_path, capsys):
    main(["--out", str(tmp_path), "--rays", "4", "--steps", "2", "--dpi", "30"])
    written = capsys.readouterr().out.split()
    assert sorted(written) == sorted(str(tmp_path / f"{name}.png") for name in FIGURES)
    for name in FIGURES:
        png = (tmp_path / f"{name}.png").read_bytes()
        assert png.startswith(b"\x89PNG") and len(png) > 1000
