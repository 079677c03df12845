#!/usr/bin/env python3
"""Reads a partition run's recording.mcap with an independent reader (the `mcap`
package of PyPI, pinned in scripts/requirements.txt) and checks what Foxglove relies on:

- the summary section: statistics, one chunk index per chunk (each with its message
  indexes), the message count per channel equal to the messages read through the chunk
  indexes and to those read in file order;
- every channel JSON-encoded with a `jsonschema` schema, and every message of every
  channel a JSON object the schema describes completely (the fields and types it
  declares, nothing else; `null` only where the schema allows it);
- the metadata record naming the run (build, scenario, partition config), the config
  named relative to the run's folder and holding the recorded text;
- `/tf` (foxglove.FrameTransform) and `/scene` (foxglove.SceneUpdate) present, and
  every scene entity's frame one of the frames on `/tf`;
- with `--recorder-json`, the recorder's own count per service equal to the MCAP's;
- the partner SDK's minimal reader (`sc_partner.mcap`, which skips metadata and the
  summary's records) reading the same messages.

Prints one line per problem and exits 1 if there is any; else prints a summary and
exits 0. Usage: mcap_check.py RECORDING.mcap [--recorder-json recorder.json]
"""

import argparse
import collections
import json
import pathlib
import sys

from mcap.reader import make_reader

METADATA_NAME = "safe-capture"
METADATA_KEYS = {
    "version",
    "git_commit",
    "scenario",
    "scenario_path",
    "partition_config",
    "partition_config_path",
}
TF_TOPIC = "/tf"
SCENE_TOPIC = "/scene"

_JSON_TYPES = {
    "object": dict,
    "array": list,
    "string": str,
    "boolean": bool,
    "null": type(None),
}


def _type_ok(value, name):
    if name == "integer":
        return isinstance(value, int) and not isinstance(value, bool)
    if name == "number":
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    return isinstance(value, _JSON_TYPES[name])


def schema_errors(schema, value, path="$"):
    """What in `value` the JSON schema `schema` does not describe (the subset of JSON
    Schema the recorder writes: type, properties, items, minItems, maxItems, minimum)."""
    errors = []
    types = schema.get("type")
    if types is not None:
        types = types if isinstance(types, list) else [types]
        if not any(_type_ok(value, t) for t in types):
            return [f"{path}: {json.dumps(value)[:60]} is not {'/'.join(types)}"]
    if isinstance(value, dict) and "properties" in schema:
        props = schema["properties"]
        for k in value.keys() - props.keys():
            errors.append(f"{path}.{k}: not in the schema")
        for k in props.keys() - value.keys():
            errors.append(f"{path}.{k}: missing")
        for k in value.keys() & props.keys():
            errors += schema_errors(props[k], value[k], f"{path}.{k}")
    if isinstance(value, list):
        if "minItems" in schema and len(value) < schema["minItems"]:
            errors.append(f"{path}: {len(value)} items < {schema['minItems']}")
        if "maxItems" in schema and len(value) > schema["maxItems"]:
            errors.append(f"{path}: {len(value)} items > {schema['maxItems']}")
        if "items" in schema:
            for i, x in enumerate(value):
                errors += schema_errors(schema["items"], x, f"{path}[{i}]")
    if "minimum" in schema and isinstance(value, (int, float)) and value < schema["minimum"]:
        errors.append(f"{path}: {value} < {schema['minimum']}")
    return errors


def check(path, recorder_json=None):
    """The problems found in the recording at `path` and a summary of it."""
    problems = []
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        if summary is None or summary.statistics is None:
            return [f"{path}: no summary section or no statistics"], {}
        stats = summary.statistics
        if not summary.chunk_indexes:
            problems.append("no chunk index")
        if len(summary.chunk_indexes) != stats.chunk_count:
            problems.append(
                f"{len(summary.chunk_indexes)} chunk indexes, statistics say {stats.chunk_count} chunks"
            )
        for ci in summary.chunk_indexes:
            if not ci.message_index_offsets:
                problems.append(f"chunk at {ci.chunk_start_offset}: no message index")
        if stats.channel_count != len(summary.channels):
            problems.append(f"statistics: {stats.channel_count} channels, summary has {len(summary.channels)}")
        for cid, ch in summary.channels.items():
            schema = summary.schemas.get(ch.schema_id)
            if ch.message_encoding != "json":
                problems.append(f"{ch.topic}: message encoding {ch.message_encoding!r}")
            if schema is None or schema.encoding != "jsonschema":
                problems.append(f"{ch.topic}: no jsonschema schema")

        # every message, through the chunk indexes (log-time order), validated
        indexed = collections.Counter()
        parsed_schemas = {}
        frames = set()
        scene_frames = set()
        for schema, channel, message in reader.iter_messages(log_time_order=True):
            indexed[channel.id] += 1
            if schema.id not in parsed_schemas:
                parsed_schemas[schema.id] = json.loads(schema.data)
            try:
                value = json.loads(message.data)
            except ValueError as e:
                problems.append(f"{channel.topic} @ {message.log_time}: not JSON ({e})")
                continue
            errs = schema_errors(parsed_schemas[schema.id], value, channel.topic)
            problems += errs[:3]
            if channel.topic == TF_TOPIC and not errs:
                frames.update((value["parent_frame_id"], value["child_frame_id"]))
            if channel.topic == SCENE_TOPIC and not errs:
                scene_frames.update(e["frame_id"] for e in value["entities"])
        for cid, n in stats.channel_message_counts.items():
            if indexed[cid] != n:
                topic = summary.channels[cid].topic
                problems.append(f"{topic}: statistics count {n}, {indexed[cid]} read through the indexes")
        if sum(indexed.values()) != stats.message_count:
            problems.append(f"statistics: {stats.message_count} messages, {sum(indexed.values())} read")

        # the same in file order, without the indexes
        f.seek(0)
        in_file = collections.Counter(
            ch.id for _, ch, _ in make_reader(f).iter_messages(log_time_order=False)
        )
        if in_file != indexed:
            problems.append("messages read in file order differ from those read through the indexes")

        metadata = list(reader.iter_metadata())
        if len(metadata) != stats.metadata_count or len(summary.metadata_indexes) != len(metadata):
            problems.append(
                f"{len(metadata)} metadata records, statistics say {stats.metadata_count}, "
                f"{len(summary.metadata_indexes)} indexed"
            )
        ours = [m for m in metadata if m.name == METADATA_NAME]
        if len(ours) != 1:
            problems.append(f"{len(ours)} metadata records named {METADATA_NAME!r}")
        else:
            missing = METADATA_KEYS - ours[0].metadata.keys()
            empty = [k for k in METADATA_KEYS & ours[0].metadata.keys() if not ours[0].metadata[k]]
            if missing or empty:
                problems.append(f"metadata: missing {sorted(missing)}, empty {sorted(empty)}")
            # the config is named relative to the run's folder (renamed after the run)
            config = ours[0].metadata.get("partition_config_path")
            if config:
                beside = pathlib.Path(path).resolve().parent / config
                if pathlib.PurePath(config).is_absolute():
                    problems.append(f"metadata: partition_config_path {config!r} is not relative to the run's folder")
                elif not beside.is_file():
                    problems.append(f"metadata: partition_config_path {config!r}: no {beside}")
                elif beside.read_text() != ours[0].metadata.get("partition_config"):
                    problems.append(f"metadata: {beside} differs from partition_config")

    by_topic = {summary.channels[cid].topic: n for cid, n in indexed.items()}
    for topic in (TF_TOPIC, SCENE_TOPIC):
        if not by_topic.get(topic):
            problems.append(f"no message on {topic}")
    if scene_frames - frames:
        problems.append(f"scene frames {sorted(scene_frames - frames)} not on {TF_TOPIC} ({sorted(frames)})")

    if recorder_json is not None:
        recorded = json.loads(pathlib.Path(recorder_json).read_text())["recorded"]
        for service, n in recorded.items():
            if by_topic.get(service, 0) != n:
                problems.append(f"{service}: recorder counted {n}, the MCAP holds {by_topic.get(service, 0)}")

    # the partner SDK's own reader (standard library only) reads the same messages
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent / "python"))
    from sc_partner import mcap as sdk_mcap

    sdk = collections.Counter(topic for topic, _, _ in sdk_mcap.messages(path))
    if sdk != collections.Counter(by_topic):
        problems.append(f"sc_partner.mcap reads {dict(sdk)}, the mcap package {by_topic}")

    return problems, {
        "messages": sum(indexed.values()),
        "channels": len(summary.channels),
        "chunks": len(summary.chunk_indexes),
        "metadata": len(metadata),
        "frames": sorted(frames),
        "per_topic": by_topic,
    }


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mcap", help="recording.mcap of a partition run")
    ap.add_argument("--recorder-json", help="the run's recorder.json (counts per service)")
    args = ap.parse_args(argv)
    try:
        problems, info = check(args.mcap, args.recorder_json)
    except Exception as e:  # a file the reader cannot read at all is a finding, not a crash
        problems, info = [f"{args.mcap}: unreadable: {type(e).__name__}: {e}"], {}
    for p in problems:
        print(f"mcap_check: {p}")
    if problems:
        print(f"mcap_check: FAILED, {len(problems)} problems in {args.mcap}")
        return 1
    print(
        "mcap_check: ok: {messages} messages on {channels} channels in {chunks} chunks, "
        "{metadata} metadata record(s), frames {frames}".format(**info)
    )
    print("mcap_check: per topic " + json.dumps(info["per_topic"], sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.exit(main())
