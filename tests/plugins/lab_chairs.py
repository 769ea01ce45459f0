"""Chairs outside the package, named by module:attribute in tests/plugins."""

import dataclasses

from drake_standup.config.chair import ChairConfig, ChairModel
from drake_standup.world.chair import chair_sdf


def box_again(config: ChairConfig) -> ChairModel:
    """The shipped box chair of the scenario's numbers, made by a plug-in."""
    return ChairModel(config.seat_height_m, sdf=chair_sdf(config))


def tall_stool(config: ChairConfig) -> ChairModel:
    """A box seat 0.25 m high, whatever the scenario's numbers say."""
    tall = dataclasses.replace(config, seat_height_m=0.25)
    return ChairModel(0.25, sdf=chair_sdf(tall))


def not_a_model(config):
    return "chair.sdf"


def floating_seat(config):
    return ChairModel(2.0, sdf=chair_sdf(config))


def no_chair_frame(config):
    return ChairModel(0.2195, sdf=chair_sdf(config).replace('link name="chair"', 'link name="x"'))
