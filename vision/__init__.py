"""Camera capture and image processing, installed as ``petriflow.vision``."""
