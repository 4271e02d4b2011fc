"""Weather from Python: scan(weather=...), its labels, the `weather` region, and bad specs."""

import numpy as np
import pytest

import groundtruth as gt

FOG, RAIN, SNOW = 150, 151, 152


def test_fog_returns_are_labelled_near_and_never_ground():
    clear = gt.scan("city", "hdl64e-roof", seed=3, weather="clear")[0]
    fog = gt.scan("city", "hdl64e-roof", seed=3, weather="fog:visibility_m=40")[0]
    is_fog = fog.valid & (fog.label == FOG)
    assert is_fog.sum() > 5000, is_fog.sum()
    assert not fog.ground[is_fog].any()
    # Fog returns come from the air a few metres in front of the sensor (the pulse's peak, ~4.6 m).
    assert 2.0 < np.median(fog.range[is_fog]) < 8.0
    # Everything else keeps its clear-weather range and label, dimmer.
    kept = fog.valid & ~is_fog
    assert (clear.valid[kept]).all()
    np.testing.assert_array_equal(clear.range[kept], fog.range[kept])
    np.testing.assert_array_equal(clear.label[kept], fog.label[kept])
    assert (fog.intensity[kept] <= clear.intensity[kept]).all()
    assert fog.intensity[kept].mean() < 0.8 * clear.intensity[kept].mean()


def test_rain_and_snow_labels_region_and_determinism():
    # Snow of 3 mm/h shows flakes (a few per cent of the returns, docs/weather.md).
    a = gt.scan("highway", "vlp16-roof", seed=1, weather="snow:rate_mm_h=3")[0]
    b = gt.scan("highway", "vlp16-roof", seed=1, weather="snow:rate_mm_h=3")[0]
    mask = a.region("weather")
    assert mask.sum() > 0
    assert (a.label[mask] == SNOW).all()
    np.testing.assert_array_equal(a.xyz, b.xyz)
    # Our segmenters rarely call particles ground.
    decisions = gt.classify(a, "learned")
    score = gt.score(a, decisions, "weather")
    assert score.false_ground_rate < 0.05, score
    # Rain of 20 mm/h: drops on about 0.36 % of the VLP-16's sky beams (calibrated on Linnhoff et
    # al. 2022, docs/weather.md; 62 in this frame), deterministic, nothing but rain as weather.
    a = gt.scan("highway", "vlp16-roof", seed=1, weather="rain:rate_mm_h=20")[0]
    b = gt.scan("highway", "vlp16-roof", seed=1, weather="rain:rate_mm_h=20")[0]
    np.testing.assert_array_equal(a.xyz, b.xyz)
    assert a.region("weather").sum() > 0
    assert (a.label[a.region("weather")] == RAIN).all()


@pytest.mark.parametrize(
    ("spec", "needle"),
    [
        ("fog:visibility_m=0.5", "visibility_m"),
        ("fog:visibility_m=nan", "visibility_m"),
        ("rain:rate_mm_h=-1", "rate_mm_h"),
        ("snow:rate_mm_h=100", "0 ..= 5"),
        ("hail:rate_mm_h=1", "clear, fog, rain, snow"),
        ("fog:rate_mm_h=3", "visibility_m"),
    ],
)
def test_bad_weather_is_a_value_error_naming_the_field(spec, needle):
    with pytest.raises(ValueError, match=needle):
        gt.scan("flat", "vlp16-roof", weather=spec)
