"""``make_vec(num_envs=100000)`` is refused at once, saying the memory it would need, instead
of building runs until the machine runs out (13 GB, still building after 4 minutes)."""

from __future__ import annotations

import gymnasium as gym
import pytest

import amsa_phys  # noqa: F401  (registers the environments)
from amsa_phys.errors import ConfigError
from amsa_phys.gym.vector import check_size


def test_a_vector_env_too_large_for_memory_is_refused_before_building() -> None:
    with pytest.raises(ConfigError) as info:
        gym.make_vec(
            "amsa_phys/Follow-v0", num_envs=100_000, vectorization_mode="vector_entry_point"
        )
    text = str(info.value)
    assert text.startswith("num_envs: 100,000 envs would need about 16.0 GB")
    assert "at most 13,421 fit" in text
    assert "\n" not in text


def test_the_bound_scales_with_the_world_and_admits_what_fits() -> None:
    check_size(13_421, 8)  # the default scenario's 8 components: fits
    with pytest.raises(ConfigError):
        check_size(13_422, 8)
    with pytest.raises(ConfigError, match="at most 1,342 fit"):
        check_size(2_000, 80)  # ten times the components: a tenth of the envs
