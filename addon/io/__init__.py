"""Files: HDR panoramas and difference images as OpenEXR, previews as PNG."""
