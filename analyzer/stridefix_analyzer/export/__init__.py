"""``stridefix export``: a walk in the tools people use.

The tracks of a StrideFix log in latitude/longitude (GeoJSON, GPX, KML) through the site's
geo-reference, and the log with the site's floor plan as an MCAP file for Foxglove. Modules:
:mod:`.georef` (the site's map frame ↔ WGS-84), :mod:`.tracks` (the pose tracks read from logs),
one writer per format (:mod:`.geojson_out`, :mod:`.gpx_out`, :mod:`.kml_out`, :mod:`.mcap_out` with
the Foxglove schemas of :mod:`.foxglove`), and :mod:`.cli`, the sub-command.
"""
