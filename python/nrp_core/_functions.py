"""Decorators that declare transceiver, preprocessing and status functions.

Decorators run bottom-up, so input decorators (@EngineDataPack, @PreprocessedDataPack) may
sit above or below @TransceiverFunction / @PreprocessingFunction: inputs declared on the
bare function are kept until the function decorator wraps it."""

_registered = []  # filled while the coordinator executes one function file


class _Input:
    __slots__ = ("keyword", "id", "preprocessed")

    def __init__(self, keyword, id, preprocessed):
        self.keyword = keyword
        self.id = id
        self.preprocessed = preprocessed


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


def _input_decorator(keyword, id, preprocessed):
    if not isinstance(keyword, str):
        raise TypeError("datapack keyword must be a string, got %r" % (keyword,))
    if not hasattr(id, "dataPackName"):
        raise TypeError("id must be a DataPackIdentifier, got %r" % (id,))
    inp = _Input(keyword, id, preprocessed)

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
