"""ClosesOnExit: `with env:` and garbage collection both call the environment's close()."""


class ClosesOnExit:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:  # noqa: BLE001 - nothing to do about it at collection
            pass
