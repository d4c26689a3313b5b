"""All of the GPU work in one command (check.py), and the payload that brings it to a lent machine."""
