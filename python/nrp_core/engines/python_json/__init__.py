"""Base class of Python engines (EngineType python_json), as in NRP-Core."""


class EngineScript:
    """Subclass this in the engine's script (NRP-Core expects the class to be named Script).

    The server sets `_name` and `_config`, advances `_time_ns` to the end of the step being
    run, then calls runLoop(timestep_ns)."""

    def __init__(self):
        self._time_ns = 0
        self._name = ""
        self._config = {}
        self._datapacks = {}

    # --- to override -------------------------------------------------------------------
    def initialize(self):
        pass

    def runLoop(self, timestep_ns):
        pass

    def shutdown(self):
        pass

    def reset(self):
        self._time_ns = 0

    # --- datapacks ---------------------------------------------------------------------
    def _registerDataPack(self, datapack_name):
        if datapack_name in self._datapacks:
            raise ValueError("datapack '%s' is already registered in engine '%s'"
                             % (datapack_name, self._name))
        self._datapacks[datapack_name] = None

    def _getDataPack(self, datapack_name):
        try:
            return self._datapacks[datapack_name]
        except KeyError:
            raise KeyError("datapack '%s' is not registered in engine '%s'"
                           % (datapack_name, self._name)) from None

    def _setDataPack(self, datapack_name, data):
        if datapack_name not in self._datapacks:
            raise KeyError("datapack '%s' is not registered in engine '%s'"
                           % (datapack_name, self._name))
        self._datapacks[datapack_name] = data

    def _advanceTime(self, timestep_ns):
        self._time_ns += timestep_ns
