"""Exporters: DXF drawings, solid meshes, CSV tables and G-code."""
