"""Reads Convoy's recordings (MCAP files, https://mcap.dev/spec) in pure Python.

    from convoy_mcap import Recording
    rec = Recording("runs/x/recording.mcap")      # checks magic, records, CRCs, indexes
    rec.metadata["convoy"]["config"]               # the run's effective config (JSON text)
    for m in rec.messages():                       # in file order
        m.topic, m.log_time, m.sequence, m.encoding, m.value

`value` is the decoded payload: a dict for json messages (tags of docs/recording.md kept;
`untag(value)` turns them into Python values), bytes for protobuf ones (with `schema_name`,
the message's full type name, and `rec.schemas[...]` its FileDescriptorSet).

A file cut short (a killed run, a full disk) reads up to its last whole chunk: `rec.complete`
is False, `rec.incomplete` says where it ends, and a McapIncompleteWarning is issued.

    /usr/bin/python3 -m convoy_mcap FILE.mcap      # topics, counts, metadata
"""
from .reader import McapError, McapIncompleteWarning, Message, Recording, untag

__all__ = ["McapError", "McapIncompleteWarning", "Message", "Recording", "untag"]
