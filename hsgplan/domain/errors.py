"""Errors for bad input. Each carries one line that says what is wrong; the CLI prints it and
exits with code 2."""


class InvalidInputError(ValueError):
    """Input that cannot be used: the message names the culprit and the reason."""


class UnknownNameError(InvalidInputError):
    """A name that is neither an object instance, a shelf, a region nor a predicate."""


class GoalSyntaxError(InvalidInputError):
    """Text that does not parse as literals."""


class InfeasibleError(InvalidInputError):
    """Literals that contradict each other or that no physical scene can satisfy."""


class UnsampledSceneError(InvalidInputError):
    """No start scene could be drawn for a goal's objects within the sampler's attempts: the
    world's limit, not an agent's failure (an evaluation records it and goes on)."""


def a(noun: str) -> str:
    """`noun` behind its indefinite article, as a message reads it ("an eval-task run")."""
    return f"{'an' if noun[:1].lower() in 'aeiou' else 'a'} {noun}"
