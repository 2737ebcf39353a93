"""Same-run performance comparisons of wmrkit against the peers a user would otherwise pick."""
