"""The truncated tensor algebra, the level-2 group and the Lyndon basis."""
