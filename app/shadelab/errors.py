"""The one exception type that the command line turns into a one-line error and exit code 2."""


class ShadeLabError(Exception):
    """Bad input or an unusable environment, explained in one line for the user.

    The CLI prints ``shadelab: error: <message>`` on stderr and exits with code 2;
    the viewer shows the message inside the app and keeps the current scene.
    """
