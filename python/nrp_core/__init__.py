"""Convoy's implementation of NRP-Core's Python API for transceiver functions."""

from nrp_core._datapacks import DataPack, DataPackIdentifier, EmptyDataPack, JsonDataPack  # noqa: F401
from nrp_core._functions import (EngineDataPack, PreprocessedDataPack,  # noqa: F401
                                 PreprocessingFunction, TransceiverFunction)

__all__ = ["DataPack", "DataPackIdentifier", "EmptyDataPack", "JsonDataPack", "EngineDataPack",
           "PreprocessedDataPack", "PreprocessingFunction", "TransceiverFunction"]
