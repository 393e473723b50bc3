"""The progress of a real line's answer: one step of the bar per run made (``caps_runs.Runs``),
the last run named in its postfix; a run asked for again (made once) does not step it."""

from snapping import caps
from snapping.caps_runs import Runs


class Bar:
    def __init__(self):
        self.n, self.postfix = 0, []

    def update(self, k):
        self.n += k

    def set_postfix_str(self, s, refresh=True):
        self.postfix.append(s)


def test_each_run_made_steps_the_bar_once():
    sp = caps.spec("bungee-cord")
    bar = Bar()
    runs = Runs(sp, 0.3, 1e-6, 1e-3, 0.0, bar=bar)
    runs.get((), 8)
    runs.get((), 8)  # made once: no second step
    runs.get(("drag",), 8)
    assert bar.n == 2 == len(runs.log)
    assert bar.postfix[0].startswith("ideal: 8 links") and bar.postfix[1].startswith("drag: 8 links")


def test_a_bar_is_optional():
    runs = Runs(caps.spec("bungee-cord"), 0.3, 1e-6, 1e-3, 0.0)
    runs.get((), 6)
    assert len(runs.log) == 1
