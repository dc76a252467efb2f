"""The error of a refused ESyS-Particle call (docs/esys.md, "Refused calls")."""


class NotSupportedError(NotImplementedError):
    """An ESyS-Particle call that Basalt's front end does not provide. The message names the ESyS call and
    says what Basalt offers instead; the front end never ignores a call silently."""


def refuse(call, offer):
    """Raises NotSupportedError for the ESyS call `call` (e.g. "LsmMpi.createExclusion"), saying `offer`."""
    raise NotSupportedError(f"{call}: not supported by Basalt's ESyS-Particle front end. {offer} "
                            "(docs/esys.md lists the supported calls)")
