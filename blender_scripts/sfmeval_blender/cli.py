"""Command line of the headless generator (shared by generate.py and ``python -m``)."""

import argparse
import json
import sys

from . import config as cfgmod


def parser():
    p = argparse.ArgumentParser(
        prog="generate.py",
        description="Render a synthetic SfM dataset with exact ground truth (sfmeval).")
    p.add_argument("--config", help="dataset config, TOML (.toml) or JSON (.json)")
    p.add_argument("--preset", help="start from a built-in preset (%s)" % ", ".join(cfgmod.preset_names()))
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override one option, e.g. --set render.samples=8 (repeatable)")
    p.add_argument("--out", help="output dataset folder")
    p.add_argument("--overwrite", action="store_true", help="replace a dataset already in --out")
    p.add_argument("--no-render", action="store_true",
                   help="build the scene and export the ground truth without rendering images")
    p.add_argument("--views", metavar="i/n|A:B",
                   help="render only these views into --out (every n-th from i, or A to B-1) and "
                        "record the part in --out/.parts/; then --finalize")
    p.add_argument("--finalize", action="store_true",
                   help="after every --views part is rendered: check them and write the ground "
                        "truth, cameras.json, dataset.json and timing.json")
    p.add_argument("--print-config", action="store_true",
                   help="print the resolved configuration as JSON and exit")
    p.add_argument("--list-presets", action="store_true", help="list the presets and exit")
    return p


def main(argv):
    args = parser().parse_args(argv)
    if args.list_presets:
        print("\n".join(cfgmod.preset_names()))
        return 0
    try:
        user = cfgmod.load_file(args.config) if args.config else {}
        if not args.config and not args.preset:
            raise cfgmod.ConfigError("give --config FILE and/or --preset NAME")
        cfg = cfgmod.resolve(user, preset=args.preset, overrides=args.set)
        if args.print_config:
            print(json.dumps(cfg, indent=1))
            return 0
        if not args.out:
            raise cfgmod.ConfigError("--out DIR is required")
        from . import parts, pipeline
        if args.views and args.finalize:
            raise cfgmod.ConfigError("--views and --finalize are separate steps")
        if args.views:
            parts.parse_views(args.views)
        if args.views or args.finalize:
            if args.overwrite or args.no_render:
                raise cfgmod.ConfigError("--overwrite and --no-render do not go with --views "
                                         "or --finalize")
            pipeline.check_not_finalized(args.out)
        else:
            pipeline.check_out_dir(args.out, args.overwrite)
    except cfgmod.ConfigError as exc:
        sys.stderr.write("sfmeval: config error: %s\n" % exc)
        return 2
    try:
        from . import steps
    except ImportError as exc:
        sys.stderr.write("sfmeval: cannot import Blender's bpy (%s): run inside Blender "
                         "(blender -b --factory-startup -P generate.py -- ...) or in a Python "
                         "with the PyPI bpy module\n" % exc)
        return 3
    try:
        if args.views:
            pipeline.render_part(cfg, args.out, args.views)
        elif args.finalize:
            pipeline.finalize(cfg, args.out)
        else:
            pipeline.generate(cfg, args.out, render=not args.no_render, overwrite=args.overwrite)
    except (cfgmod.ConfigError, steps.GenerationError) as exc:
        sys.stderr.write("sfmeval: error: %s\n" % exc)
        return 1
    return 0
