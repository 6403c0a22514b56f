"""Convoy's implementation of NRP-Core's Python API for transceiver functions."""

from nrp_core._datapacks import (DataPack, DataPackIdentifier, EmptyDataPack,  # noqa: F401
                                 JsonDataPack, JsonRawData, RawData)
from nrp_core._functions import (EngineDataPack, PreprocessedDataPack,  # noqa: F401
                                 PreprocessingFunction, SimulationIteration, SimulationTime,
                                 StatusFunction, TransceiverFunction)

__all__ = ["DataPack", "DataPackIdentifier", "EmptyDataPack", "JsonDataPack", "RawData",
           "JsonRawData", "EngineDataPack", "PreprocessedDataPack", "PreprocessingFunction",
           "TransceiverFunction", "StatusFunction", "SimulationIteration", "SimulationTime"]
