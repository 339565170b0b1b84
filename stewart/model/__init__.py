"""The platform's model: its parameters (:mod:`~stewart.model.params`, presets, parameter
files), kinematics, the conditions under which the model is undefined and the errors raised
for them, argument checks, the compiled model's facade :class:`~stewart.Platform`
(:mod:`~stewart.model.platform`) and which poses it can reach
(:mod:`~stewart.model.reachability`).

Everything here but :mod:`~stewart.model.platform` and the reachability test (which
evaluate the compiled model) imports and works without the compiled extension.

**A platform argument.** Every public function of the package that takes a platform
accepts either a :class:`~stewart.Platform` or a :class:`~stewart.PlatformParams`, with the
same result, and converts it once, where it enters: a function that evaluates the compiled
model by :func:`~stewart.model.platform.as_platform` (a ``PlatformParams`` is compiled into
a ``Platform``), a function that works on the parameters alone (the kinematics of
:mod:`~stewart.model.kinematics`, the oracles) by :func:`~stewart.model.params.platform_params`
(a ``Platform`` gives its :attr:`~stewart.Platform.params`). Anything else raises
:class:`~stewart.WrongTypeError` naming the argument. The functions they call inside
take the converted value and do not check it again; a public function of another module
that they call (the workspace check of :mod:`~stewart.model.reachability`, say) is an entry
of its own."""

from .._modules import on_first_use

__getattr__ = on_first_use(__name__, __path__)
