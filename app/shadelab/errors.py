"""The one exception type that the command line turns into a one-line error and exit code 2."""


class ShadeLabError(Exception):
    """Bad input or an unusable environment, explained in one line for the user.

    The CLI prints ``shadelab: error: <message>`` on stderr and exits with code 2;
    the viewer shows the message inside the app and keeps the current scene.
    The message is made one line here, whatever it quotes (a key with a newline, a control
    character, a huge value): see :func:`one_line`.
    """

    def __init__(self, message: object = "", *args: object):
        super().__init__(one_line(str(message)), *args)


MAX_MESSAGE = 1000  # characters


def one_line(text: str, limit: int = MAX_MESSAGE) -> str:
    """Escape line breaks and other control characters; cut a message past ``limit``."""
    out = "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)
    return out if len(out) <= limit else out[: limit - 3] + "..."
