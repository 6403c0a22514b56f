"""JSON datapacks, as in NRP-Core's nrp_core.data.nrp_json."""

from nrp_core._datapacks import DataPackIdentifier, JsonDataPack, JsonRawData  # noqa: F401

__all__ = ["JsonDataPack", "JsonRawData", "DataPackIdentifier"]
