"""Reading measured records (qc_control.Measurement): units, resampling, refusals."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import qc_control as qc


def _frame(n=200, fs=100.0):
    t = np.arange(n) / fs
    return pd.DataFrame(
        {
            "time_s": t,
            "base_mm": 5.0 * np.sin(2 * np.pi * t),
            "force_kN": np.cos(t),
            "acc": np.sin(3 * t),
        }
    )


def test_from_csv_maps_columns_and_scales_to_si(tmp_path):
    path = tmp_path / "rig.csv"
    path.write_text("# rig test\n" + _frame().to_csv(index=False), encoding="utf-8")
    m = qc.Measurement.from_csv(
        path,
        time="time_s",
        columns={"zr": "base_mm", "fa": "force_kN", "body_acc": "acc"},
        units={"zr": "mm", "fa": "kN"},
        scale={"fa": -1.0},
    )
    frame = _frame()
    assert m.inputs == ("zr", "fa") and m.outputs == ("body_acc",)
    np.testing.assert_allclose(m["zr"], frame.base_mm * 1e-3, rtol=1e-15)
    np.testing.assert_allclose(m["fa"], -1e3 * frame.force_kN, rtol=1e-15)  # kN, sign flipped
    assert m.dt == pytest.approx(0.01, rel=1e-12) and m.notes == ()


def test_uneven_time_is_resampled_with_a_note():
    rng = np.random.default_rng(0)
    t = np.arange(500) * 0.01 + rng.uniform(-1e-4, 1e-4, 500)  # 1 % jitter, no gap
    m = qc.Measurement(t, body_acc=np.sin(2 * np.pi * t))
    assert np.ptp(np.diff(m.t)) < 1e-12
    assert "resampled" in m.notes[0]
    # linear interpolation of a 1 Hz sine at 100 Hz: error below (2π·0.01)²/8 ≈ 5e-4
    np.testing.assert_allclose(m["body_acc"], np.sin(2 * np.pi * m.t), atol=5e-4)


@pytest.mark.parametrize(
    "edit, match",
    [
        (
            lambda f: f.__setitem__("acc", f.acc.where(f.index != 17)),
            r"'acc' \(body_acc\) is not a "
            r"number at row 19 \(t = 0.17 s\)",
        ),
        (
            lambda f: f.__setitem__("time_s", f.time_s.where(f.index != 50, 0.2)),
            r"time column 'time_s' does not increase at row 52",
        ),
        (
            lambda f: f.__setitem__("time_s", f.time_s + (f.index >= 80) * 0.5),
            r"time column 'time_s' has a gap between row 81 and row 82",
        ),
    ],
    ids=["nan", "backwards", "gap"],
)
def test_bad_records_name_the_column_and_the_row(tmp_path, edit, match):
    frame = _frame()
    edit(frame)
    path = tmp_path / "bad.csv"
    frame.to_csv(path, index=False)
    with pytest.raises(ValueError, match=match):
        # rows are the file's lines: the header is line 1, sample i is line i + 2
        qc.Measurement.from_csv(path, time="time_s", columns={"zr": "base_mm", "body_acc": "acc"})


def test_unknown_label_unit_and_column():
    f = _frame()
    with pytest.raises(ValueError, match="unknown label 'speed' for column 'acc'"):
        qc.Measurement.from_frame(f, time="time_s", columns={"speed": "acc"})
    with pytest.raises(ValueError, match="column 'accel' .* is not among"):
        qc.Measurement.from_frame(f, time="time_s", columns={"body_acc": "accel"})
    with pytest.raises(ValueError, match="unit 'furlong' of 'zr'"):
        qc.Measurement.from_frame(
            f, time="time_s", columns={"zr": "base_mm"}, units={"zr": "furlong"}
        )
    with pytest.raises(ValueError, match="time column 't' is not among"):
        qc.Measurement.from_frame(f)
    with pytest.raises(ValueError, match="shape"):
        qc.Measurement(np.arange(10.0), zr=np.zeros(9))


def test_window_and_frame():
    t = np.arange(0, 10, 0.01)
    m = qc.Measurement(t, zr=np.sin(t), xs=np.cos(t))
    w = m.window(2.0, 4.0)
    assert w.t[0] == pytest.approx(2.0) and w.t[-1] == pytest.approx(4.0)
    np.testing.assert_array_equal(w["xs"], np.cos(w.t))
    assert list(m.frame().columns) == ["zr", "xs"]
    with pytest.raises(KeyError, match="no signal 'fa'"):
        m["fa"]


def test_a_csv_not_in_utf8_names_the_file_and_the_fix(tmp_path):
    """Issue 39 item 14: "'utf-8' codec can't decode byte 0xff" named neither the
    file nor what to do."""
    path = tmp_path / "logger.csv"
    path.write_bytes(b"time_s,zr\n0,1\n0.1,2\n0.2,\xb5\n")  # cp1252's µ
    with pytest.raises(ValueError, match=r"logger.csv' is not UTF-8 text .*save it as 'CSV UTF-8'"):
        qc.Measurement.from_csv(path, time="time_s")
