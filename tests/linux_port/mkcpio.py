#!/usr/bin/env python3
"""mkcpio.py ROOT OUT.cpio.gz - an initramfs (cpio "newc", gzip) of the tree ROOT, plus the
two device nodes the kernel needs before devtmpfs is mounted (/dev/console: init's output;
/dev/null). Written here rather than with cpio + mknod so that building the image needs no
root: the nodes exist only inside the archive."""
import gzip
import os
import stat
import sys


def header(ino, mode, nlink, size, rdev_major, rdev_minor, name):
    fields = [ino, mode, 0, 0, nlink, 0, size, 0, 0, rdev_major, rdev_minor,
              len(name) + 1, 0]
    return b"070701" + b"".join(b"%08X" % f for f in fields)


def pad(n):
    return b"\0" * ((4 - n % 4) % 4)


def entry(out, ino, mode, name, data=b"", rdev=(0, 0)):
    nlink = 2 if stat.S_ISDIR(mode) else 1
    h = header(ino, mode, nlink, len(data), rdev[0], rdev[1], name)
    out.write(h + name.encode() + b"\0")
    out.write(pad(len(h) + len(name) + 1))
    out.write(data)
    out.write(pad(len(data)))


def main():
    root, dest = sys.argv[1], sys.argv[2]
    ino = 1
    with gzip.open(dest, "wb", compresslevel=1) as out:
        for dirpath, dirnames, filenames in os.walk(root):
            dirnames.sort()
            rel = os.path.relpath(dirpath, root)
            if rel != ".":
                entry(out, ino, stat.S_IFDIR | 0o755, rel)
                ino += 1
            for f in sorted(filenames + [d for d in dirnames
                                         if os.path.islink(os.path.join(dirpath, d))]):
                path = os.path.join(dirpath, f)
                name = os.path.normpath(os.path.join(rel, f))
                st = os.lstat(path)
                if stat.S_ISLNK(st.st_mode):
                    entry(out, ino, stat.S_IFLNK | 0o777, name, os.readlink(path).encode())
                elif stat.S_ISREG(st.st_mode):
                    with open(path, "rb") as fh:
                        entry(out, ino, stat.S_IFREG | (st.st_mode & 0o777), name, fh.read())
                ino += 1
        for name, major, minor, perm in (("dev/console", 5, 1, 0o600), ("dev/null", 1, 3, 0o666)):
            entry(out, ino, stat.S_IFCHR | perm, name, rdev=(major, minor))
            ino += 1
        entry(out, 0, 0, "TRAILER!!!")


if __name__ == "__main__":
    main()
