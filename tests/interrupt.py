"""Ctrl-C in the middle of a run, made deterministic: SIGINT is raised from the progress
bar's first update past a given simulated time, as a user's key press would arrive."""

import signal

from stewart.motion import simulation


def press_ctrl_c_after(monkeypatch, after: float) -> None:
    update = simulation._Progress.update

    def press(self, t):
        if t > after and not getattr(self, "pressed", False):
            self.pressed = True
            signal.raise_signal(signal.SIGINT)
        update(self, t)

    monkeypatch.setattr(simulation._Progress, "update", press)
