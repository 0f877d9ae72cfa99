"""``stridefix export``: a walk as GeoJSON, GPX or KML (latitude/longitude) or as MCAP for Foxglove.

Registers the sub-command and maps its errors to the exit status; the work is in the format modules
of this package. The map formats need the site's geo-reference; MCAP uses it when there is one.
"""

from __future__ import annotations

import argparse
import datetime
import os
import sys

from stridefix_common.exits import EXIT_FAILURE, EXIT_OK, EXIT_USAGE, input_error_status

#: format → the file suffixes that choose it when --format is not given
FORMATS = {"geojson": (".geojson", ".json"), "gpx": (".gpx",), "kml": (".kml",), "mcap": (".mcap",)}
PROG = "stridefix export"


def _utc(text: str) -> datetime.datetime:
    try:
        when = datetime.datetime.fromisoformat(text.replace("Z", "+00:00"))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not an ISO 8601 time (e.g. 2024-05-02T09:30:00Z)"
        ) from None
    return when if when.tzinfo else when.replace(tzinfo=datetime.timezone.utc)


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Declare the ``export`` sub-command and its options."""
    p = subparsers.add_parser(
        "export",
        help="write a walk as GeoJSON, GPX, KML (latitude/longitude) or MCAP (Foxglove)",
        description="Write the pose tracks of LCM logs in latitude/longitude through the site's "
        "geo-reference (GeoJSON for QGIS or geojson.io, GPX, KML for Google Earth), a track per "
        "scheme and a part per floor, the floor's height as elevation; or the poses, steps, fixes and "
        "the site's floor plan as an MCAP file for Foxglove (docs/tools.md). The map formats need a "
        "site with a geo-reference (radiomap build --origin-deg, or [geo] in building.toml).",
    )
    p.add_argument("logs", nargs="+", metavar="LOG", help="stridefixd LCM log(s)")
    p.add_argument("--site", required=True, metavar="SITE.sfsite", help="the site file the walk ran with")
    p.add_argument("--out", required=True, metavar="FILE", help="the file to write")
    p.add_argument(
        "--format",
        choices=sorted(FORMATS),
        default=None,
        help="output format (default: from the --out suffix: .geojson/.json, .gpx, .kml, .mcap)",
    )
    p.add_argument(
        "--scheme",
        default=None,
        metavar="NAME|all",
        help="the track(s): a scheme's name, or all for every scheme (default: the primary pose, the "
        "POSE channel); MCAP always carries every pose channel",
    )
    p.add_argument(
        "--start-utc",
        type=_utc,
        default=None,
        metavar="TIME",
        help="UTC time of board time 0, ISO 8601 (default 1970-01-01T00:00:00Z: board time as it is)",
    )
    return p


def _format(args: argparse.Namespace) -> str | None:
    if args.format:
        return str(args.format)
    suffix = os.path.splitext(args.out)[1].lower()
    return next((name for name, suffixes in FORMATS.items() if suffix in suffixes), None)


def run(args: argparse.Namespace) -> int:
    """Entry point of ``stridefix export``; returns the exit status."""
    from stridefix_analyzer.export import georef, tracks
    from stridefix_analyzer.export.extra import MissingExtraError
    from stridefix_analyzer.io.lcmfile import LogReadError
    from stridefix_analyzer.schemes import UnknownSchemeError
    from stridefix_analyzer.scoring.floor_height import from_table

    fmt = _format(args)
    if fmt is None:
        return _error(
            f"--out {args.out}: say --format {'|'.join(sorted(FORMATS))} (the suffix names none)", EXIT_USAGE
        )
    start = args.start_utc or tracks.EPOCH
    try:
        site = georef.read_site_file(args.site)
        if fmt == "mcap":
            from stridefix_analyzer.export.mcap_out import write_mcap

            geo = georef.from_site(site, args.site) if site.has_geo else None
            floors = from_table(site.floor_height_m, site.lowest_floor, f"site {args.site}")
            counts = write_mcap(args.out, args.logs, site, floors, geo, start)
            print(f"wrote {args.out}: {sum(counts.values())} messages on {len(counts)} topics")
            return EXIT_OK
        geo = georef.from_site(site, args.site)
        found = tracks.read_tracks(args.logs, args.scheme)
        if fmt == "geojson":
            from stridefix_analyzer.export.geojson_out import write_geojson as write
        elif fmt == "gpx":
            from stridefix_analyzer.export.gpx_out import write_gpx as write
        else:
            from stridefix_analyzer.export.kml_out import write_kml as write
        write(args.out, found, geo, start)
    except (LogReadError, tracks.TrackError) as exc:
        return _error(str(exc), input_error_status(exc))
    except (georef.GeoRefError, UnknownSchemeError) as exc:
        return _error(str(exc), EXIT_USAGE)
    except MissingExtraError as exc:
        return _error(str(exc), EXIT_FAILURE)
    except OSError as exc:
        return _error(f"{args.out}: cannot write: {exc.strerror or exc}", EXIT_FAILURE)
    poses = sum(len(t) for t in found)
    print(f"wrote {args.out}: {len(found)} track(s) ({', '.join(t.name for t in found)}), {poses} poses")
    return EXIT_OK


def _error(text: str, status: int) -> int:
    print(f"{PROG}: error: {text}", file=sys.stderr)
    return status
