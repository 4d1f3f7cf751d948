"""The acceptance scripts' tally: each check prints ok or FAIL with its detail."""


class Checks:
    def __init__(self):
        self.passed = 0
        self.failed = 0

    def check(self, name, ok, detail=""):
        print("%s  %s%s" % ("ok  " if ok else "FAIL", name, ": " + detail if detail else ""))
        if ok:
            self.passed += 1
        else:
            self.failed += 1
