"""The test scripts' tally (acceptance, urdf, realdata): each check prints ok or FAIL with its
detail, at once (a long run shows where it is)."""


class Checks:
    def __init__(self):
        self.passed = 0
        self.failed = 0

    def check(self, name, ok, detail=""):
        print("%s  %s%s" % ("ok  " if ok else "FAIL", name, ": " + detail if detail else ""),
              flush=True)
        if ok:
            self.passed += 1
        else:
            self.failed += 1
