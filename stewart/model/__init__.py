"""The platform's model: its parameters (:mod:`~stewart.model.params`, presets, parameter
files), kinematics, the conditions under which the model is undefined and the errors raised
for them, argument checks, the compiled model's facade :class:`~stewart.Platform`
(:mod:`~stewart.model.platform`) and which poses it can reach
(:mod:`~stewart.model.reachability`).

Everything here but :mod:`~stewart.model.platform` and the reachability test (which
evaluate the compiled model) imports and works without the compiled extension."""
