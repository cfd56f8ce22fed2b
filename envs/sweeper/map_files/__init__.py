"""The shipped sweeper maps as text bitmaps (a package so that wheels carry them)."""
