"""Tests for rtpy.cli.options: the types of the rendering commands' options and the
render settings read from flags and --set."""

from __future__ import annotations

import argparse

import pytest

from rtpy.cli.options import (
    MAX_WORKERS,
    UsageError,
    add_setting_options,
    given_settings,
    parse_set,
    read_value,
    seconds,
    shown,
    worker_count,
)


def test_seconds_are_above_zero_or_from_zero_and_below_a_million():
    assert seconds("2.5") == 2.5
    assert seconds("0", zero=True) == 0.0
    for text, zero in [("0", False), ("-1", True), ("1e6", False), ("nan", True), ("x", False)]:
        with pytest.raises(argparse.ArgumentTypeError):
            seconds(text, zero=zero)


def test_worker_counts_are_whole_numbers_up_to_the_cap():
    assert worker_count("1") == 1 and worker_count(str(MAX_WORKERS)) == MAX_WORKERS
    for text in ("0", str(MAX_WORKERS + 1), "1.5", "two"):
        with pytest.raises(argparse.ArgumentTypeError):
            worker_count(text)


def test_values_are_read_as_toml_or_kept_as_words():
    assert read_value("2", "--spp") == 2
    assert read_value("[0.1, 0.2, 0.3]", "--set background") == [0.1, 0.2, 0.3]
    assert read_value(" srgb ", "--set gamma") == "srgb"
    with pytest.raises(UsageError, match="--set gamma: expected one value on one line"):
        read_value("1\nspp = 3", "--set gamma")


def test_set_names_its_key_and_refuses_what_is_no_setting():
    assert parse_set(["spp=4", "nee = false"]) == {"spp": 4, "nee": False}
    with pytest.raises(UsageError, match="expected KEY=VALUE"):
        parse_set(["spp"])
    with pytest.raises(UsageError, match="--set sppp"):
        parse_set(["sppp=4"])
    assert shown("a\nb") == "'a\\nb'" and shown("plain") == "plain"


def test_a_flag_and_set_of_one_key_are_refused_together():
    parser = argparse.ArgumentParser()
    parser.add_argument("--time", dest="time_limit")
    add_setting_options(parser)
    args = parser.parse_args(["--spp", "8", "--set", "seed=3"])
    assert given_settings(args) == {"spp": ("--spp", 8), "seed": ("--set seed", 3)}
    args = parser.parse_args(["--spp", "8", "--set", "spp=3"])
    with pytest.raises(UsageError, match="--spp and --set spp set one value"):
        given_settings(args)
