"""FMU behaviour does not depend on how a host computes its communication times: this master
multiplies the step (start + k h), libcosim counts integer nanoseconds, Ecos adds the step up."""

import itertools

from aotv_cosim.physics.shuttle_pitch import BackwardRates


def kept_steps(times, spacing=1.0):
    """Indices of the times the pitch vehicle's rate sampler keeps."""
    rates, kept = BackwardRates(spacing), []
    for k, t in enumerate(times):
        rates.add(t, 7000.0, 0.0, 0.9)
        if rates.samples[-1][0] == t:
            kept.append(k)
    return kept


def test_pitch_rate_samples_are_the_same_on_added_up_and_multiplied_clocks():
    for step in (0.005, 0.01, 0.02, 0.05):
        n = round(600.0 / step)
        multiplied = [k * step for k in range(n + 1)]
        added = list(itertools.accumulate([0.0] + [step] * n))
        assert added != multiplied  # the clocks do differ in their last bits
        assert kept_steps(added) == kept_steps(multiplied) == list(range(0, n + 1, round(1.0 / step)))
