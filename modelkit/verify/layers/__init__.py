"""The layers: each compares one property of the written robot across the engines."""
