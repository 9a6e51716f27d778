"""Configuration space of the surveillance problem (Secs. 3-4)."""
