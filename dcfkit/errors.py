"""Exceptions raised by dcfkit. Each names what was wrong and where."""


class DcfkitError(Exception):
    """Base class of every error dcfkit raises on purpose."""


class ConfigError(DcfkitError, ValueError):
    """A config file, key or value is wrong (the message names the file and key)."""


class RegistryError(DcfkitError, LookupError):
    """A component name is unknown or registered twice."""


class InputError(DcfkitError, ValueError):
    """An image or box given to a tracker is unusable (the message says which frame)."""


class TrackingError(DcfkitError, RuntimeError):
    """Tracking could not continue on a frame (the message names the frame)."""
