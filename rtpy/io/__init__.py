"""Scene files, images, the bundled scenes and the command line."""
