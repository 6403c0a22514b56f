"""Decorators that declare transceiver, preprocessing and status functions.

Decorators run bottom-up, so input decorators (@EngineDataPack, @PreprocessedDataPack,
@SimulationIteration, @SimulationTime) may sit above or below @TransceiverFunction /
@PreprocessingFunction / @StatusFunction: inputs declared on the bare function are kept until
the function decorator wraps it."""

_registered = []  # filled while the coordinator executes one function file


class _Input:
    __slots__ = ("keyword", "id", "preprocessed", "kind")

    def __init__(self, keyword, id, preprocessed, kind="datapack"):
        self.keyword = keyword
        self.id = id
        self.preprocessed = preprocessed
        self.kind = kind  # "datapack", "iteration" or "time"


class _Function:
    kind = "TransceiverFunction"

    def __init__(self, engine_name, function):
        if not isinstance(engine_name, str):
            raise TypeError("%s needs an engine name (a string), got %r" % (self.kind, engine_name))
        self.engine_name = engine_name
        self.function = function
        self.inputs = list(reversed(getattr(function, "_nrp_inputs", [])))
        self.__name__ = getattr(function, "__name__", "function")
        self.__doc__ = getattr(function, "__doc__", None)
        _registered.append(self)

    def add_input(self, inp):
        for existing in self.inputs:
            if existing.keyword == inp.keyword:
                raise ValueError("%s '%s': input keyword '%s' declared twice"
                                 % (self.kind, self.__name__, inp.keyword))
        self.inputs.insert(0, inp)

    def __call__(self, *args, **kwargs):
        return self.function(*args, **kwargs)


class _Transceiver(_Function):
    kind = "TransceiverFunction"


class _Preprocessing(_Function):
    kind = "PreprocessingFunction"


class _Status(_Function):
    """The status function: linked to no engine, run after the transceiver functions of
    every loop cycle. It returns (done, [data]): done ends the run (standalone) or the
    client's run_until_timeout(); the data (RawData or datapacks) go to the client."""
    kind = "StatusFunction"

    def __init__(self, function):
        _Function.__init__(self, "", function)


def _check_keyword(keyword, what):
    if not isinstance(keyword, str):
        raise TypeError("%s keyword must be a string, got %r" % (what, keyword))


def _input_decorator(keyword, id, preprocessed, kind="datapack"):
    if kind == "datapack":
        _check_keyword(keyword, "datapack")
        if not hasattr(id, "dataPackName"):
            raise TypeError("id must be a DataPackIdentifier, got %r" % (id,))
    inp = _Input(keyword, id, preprocessed, kind)

    def wrap(target):
        if isinstance(target, _Function):
            target.add_input(inp)
        else:
            lst = getattr(target, "_nrp_inputs", None)
            if lst is None:
                lst = []
                target._nrp_inputs = lst
            lst.append(inp)
        return target

    return wrap


def EngineDataPack(keyword, id):
    """Declares an input: datapack `id` read from its engine, passed as argument `keyword`."""
    return _input_decorator(keyword, id, False)


def PreprocessedDataPack(keyword, id):
    """Declares an input produced by a preprocessing function (kept in the local cache)."""
    return _input_decorator(keyword, id, True)


def TransceiverFunction(engine_name):
    """Declares a transceiver function linked to `engine_name`. It returns a list of
    datapacks, which are sent to the engines they name."""
    return lambda function: _Transceiver(engine_name, function)


def PreprocessingFunction(engine_name):
    """Declares a preprocessing function of `engine_name`: its inputs come from that engine
    only, and the datapacks it returns stay in the coordinator's local cache."""
    return lambda function: _Preprocessing(engine_name, function)


def SimulationIteration(keyword):
    """Passes the number of the loop cycle (0 for the first) as argument `keyword`."""
    _check_keyword(keyword, "SimulationIteration")
    return _input_decorator(keyword, None, False, "iteration")


def SimulationTime(keyword):
    """Passes the simulated time of the loop cycle, in nanoseconds, as argument `keyword`."""
    _check_keyword(keyword, "SimulationTime")
    return _input_decorator(keyword, None, False, "time")


def StatusFunction():
    """Declares the status function (config key StatusFunction; at most one). It returns a
    tuple (done, [data]): done (a bool) ends the run cleanly when true; data are RawData
    objects (e.g. JsonRawData) or datapacks, which a client of the NRP-Core server receives."""
    return lambda function: _Status(function)
