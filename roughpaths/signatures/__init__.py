"""Signatures and log-signatures of paths and rough paths, at any depth, with their gradients."""
