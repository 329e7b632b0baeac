"""Speed against error: `python -m rtpy bench`."""
