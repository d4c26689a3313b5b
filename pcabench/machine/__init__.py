"""This machine: its hardware profile and its memory."""
