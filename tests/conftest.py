"""Hypothesis profiles: "dev" explores; "ci" (selected when CI is set) is derandomized, so runs are identical."""

import os

from hypothesis import HealthCheck, settings

# derandomize=False explicitly: with CI set, Hypothesis's own defaults (which profiles inherit) derandomize
settings.register_profile("dev", max_examples=100, deadline=None, derandomize=False)
settings.register_profile(
    "ci", max_examples=100, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow]
)
# HYPOTHESIS_PROFILE, when set, wins over CI: .ci/run's random-seed step runs "dev" (--hypothesis-seed is ignored
# under derandomize=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if os.environ.get("CI") else "dev"))
