"""The person as a body (issue 32, first part): de Leva's (1996) male segments scaled
to two people, checked against the table's numbers written out here by hand."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.multibody.plant import MultibodyPlant

from drake_standup.helper.anthropometry import DE_LEVA_MALE, add_person

PEOPLE = [(1.55, 50.0), (1.90, 100.0)]
# de Leva 1996, Table 4 (male) and the segments' lengths on 1741 mm: (mass %, length mm,
# CoM % from the first landmark); the first landmark is the body origin for the limbs,
# the second for trunk and head (they stack up from it).
TABLE = {
    "upper_arm": (2.71, 281.7, 57.72),
    "forearm": (1.62, 268.9, 45.74),
    "hand": (0.61, 86.2, 79.00),
    "thigh": (14.16, 422.2, 40.95),
    "shank": (4.33, 434.0, 44.59),
    "lower_trunk": (11.17, 145.7, 61.15),
    "middle_trunk": (16.33, 215.5, 45.02),
    "upper_trunk": (15.96, 242.1, 50.66),
    "head": (6.94, 242.9, 50.02),
}
LIMBS = ("upper_arm", "forearm", "hand", "thigh", "shank")


def _person(height_m, mass_kg):
    plant = MultibodyPlant(0.0)
    person = add_person(plant, height_m, mass_kg)
    plant.Finalize()
    return plant, person, plant.CreateDefaultContext()


def test_the_table_accounts_for_the_whole_body():
    bilateral = ("upper_arm", "forearm", "hand", "thigh", "shank", "foot")
    total = sum(s.mass * (2 if n in bilateral else 1) for n, s in DE_LEVA_MALE.items())
    assert total == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize(("height_m", "mass_kg"), PEOPLE)
def test_segments_are_the_tables(height_m, mass_kg):
    """Each segment's mass, centre of mass and length are the table's, scaled to the
    person; the total mass is the person's and the vertex stands at their height."""
    plant, person, context = _person(height_m, mass_kg)
    scale = height_m / 1.741
    assert plant.CalcTotalMass(context, [person.model_instance]) == pytest.approx(
        mass_kg, rel=1e-12
    )
    vertex = plant.GetFrameByName("vertex").CalcPoseInWorld(context).translation()
    assert vertex[2] == pytest.approx(height_m, abs=1e-12)
    for name, (mass_pct, length_mm, com_pct) in TABLE.items():
        length = length_mm / 1000.0 * scale
        first = name in LIMBS or name == "lower_trunk"  # hangs from its first landmark
        along = com_pct / 100.0 if first else 1.0 - com_pct / 100.0
        down = -1.0 if first else 1.0
        for key in [f"{side}_{name}" for side in ("left", "right")] if name in LIMBS else [name]:
            inertia = plant.GetBodyByName(key).default_spatial_inertia()
            assert inertia.get_mass() == pytest.approx(mass_pct / 100.0 * mass_kg, rel=1e-12)
            np.testing.assert_allclose(
                inertia.get_com(), [0.0, 0.0, down * along * length], atol=1e-12
            )
    # Lengths between joints, in the world: shoulder - elbow - wrist, hip - knee - ankle.
    for side in ("left", "right"):
        points = {
            n: plant.GetBodyByName(f"{side}_{n}").EvalPoseInWorld(context).translation()
            for n in ("upper_arm", "forearm", "hand", "thigh", "shank", "foot")
        }
        for a, b, mm in (
            ("upper_arm", "forearm", 281.7),
            ("forearm", "hand", 268.9),
            ("thigh", "shank", 422.2),
            ("shank", "foot", 434.0),
        ):
            assert np.linalg.norm(points[b] - points[a]) == pytest.approx(mm / 1000 * scale)


@pytest.mark.parametrize(("height_m", "mass_kg"), PEOPLE)
def test_radii_of_gyration_give_the_central_inertia(height_m, mass_kg):
    """About its CoM the upper arm's inertia is m (r L)^2 on each axis, r = 28.5, 26.9,
    15.8 % (de Leva: sagittal, transverse, longitudinal)."""
    plant, _, _ = _person(height_m, mass_kg)
    inertia = plant.GetBodyByName("left_upper_arm").default_spatial_inertia()
    central = inertia.Shift(inertia.get_com()).CalcRotationalInertia().CopyToFullMatrix3()
    m, L = 0.0271 * mass_kg, 0.2817 * height_m / 1.741
    np.testing.assert_allclose(
        np.diag(central), [m * (r * L) ** 2 for r in (0.285, 0.269, 0.158)], rtol=1e-9
    )
    assert np.abs(central - np.diag(np.diag(central))).max() < 1e-12
