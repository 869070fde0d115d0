#!/usr/bin/env python3
"""Mutation score: machine-made one-line bugs in a C++ file, and how many the tests catch.

For each FILE it generates every mutant of a fixed set of operators (below), samples N of them
with SEED, and for each sampled mutant: writes it into a scratch copy of the tree, builds the
sim preset's test binaries that cover FILE (tools/mutation_map.txt), runs their ctest entries
one at a time, cheapest first, up to the first that fails, each with a timeout, and restores the
file. A mutant is

  caught          it built and a test failed
  timed out       it built and a test ran past the timeout (an endless loop; counts as caught)
  survived        it built and every test passed
  not compiling   the build failed (left out of the score)

score = (caught + timed out) / (sampled - not compiling). docs/testing.md, "Mutation score".

  tools/mutation_score.py [--n N] [--seed SEED] [--skip K] [--json] [--list] FILE...

--skip K runs only the sample's mutants after its first K (in the listed order): a run that
was stopped goes on from where it stopped, at the same seed on the same file. The skipped ones
are reported as not run and left out of the score; their outcomes are the stopped run's.

The scratch copy (--scratch, default ${TMPDIR:-/tmp}/boticelli-mutation-score) and its build
are kept between runs, so each mutant costs an incremental build of one object and a link.
Python 3 standard library only.
"""

import argparse
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, field

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MAP_FILE = os.path.join(ROOT, "tools", "mutation_map.txt")


@dataclass
class Mutant:
    line: int  # 1-based
    col: int  # 0-based start of the replaced text ("" line: the whole line removed)
    old: str
    new: str
    kind: str
    outcome: str = ""
    seconds: float = 0.0

    def describe(self):
        if self.kind == "statement removed":
            return f"{self.kind}: {self.old.strip()}"
        return f"{self.kind}: '{self.old}' -> '{self.new}'"


@dataclass
class FileResult:
    file: str
    binaries: list
    seed: int
    generated: int = 0
    sampled: int = 0
    caught: int = 0
    survived: int = 0
    timed_out: int = 0
    not_compiling: int = 0
    not_run: int = 0  # the first --skip of the sample: a stopped run's, reported by it
    wall_s: float = 0.0
    error: str = ""
    mutants: list = field(default_factory=list)

    def score(self):
        built = self.sampled - self.not_run - self.not_compiling
        return None if built == 0 else (self.caught + self.timed_out) / built


# ---------------------------------------------------------------------------------------------
# Which characters are code: not comments, string or character literals, preprocessor lines.


def code_mask(text):
    mask = [False] * len(text)
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c in " \t":
            i += 1
            continue
        if line_start and c == "#":  # a preprocessor line, with its continuations
            while i < n and not (text[i] == "\n" and text[i - 1] != "\\"):
                i += 1
            continue
        line_start = False
        if text.startswith("//", i):
            while i < n and text[i] != "\n":
                i += 1
            continue
        if text.startswith("/*", i):
            end = text.find("*/", i + 2)
            i = n if end < 0 else end + 2
            continue
        raw = re.match(r'R"([^()\\ ]{0,16})\(', text[i:i + 20])
        if raw and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            end = text.find(")" + raw.group(1) + '"', i)
            i = n if end < 0 else end + len(raw.group(1)) + 2
            continue
        if c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # a digit separator: 1'000
                mask[i] = True
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            i = j + 1
            continue
        if c == "\n":
            line_start = True
        else:
            mask[i] = True
        i += 1
    return mask


# ---------------------------------------------------------------------------------------------
# The operators. Binary operators are matched with a space either side (clang-format's layout),
# which keeps template brackets, ->, << and pointer declarations out.

REPLACEMENTS = [
    # (pattern, replacements, kind)
    (r" < ", [" <= ", " >= "], "comparison"),
    (r" <= ", [" < ", " > "], "comparison"),
    (r" > ", [" >= ", " <= "], "comparison"),
    (r" >= ", [" > ", " < "], "comparison"),
    (r" == ", [" != "], "comparison"),
    (r" != ", [" == "], "comparison"),
    (r" && ", [" || "], "logical"),
    (r" \|\| ", [" && "], "logical"),
    (r" \+ ", [" - "], "arithmetic"),
    (r" - ", [" + "], "arithmetic"),
    (r" \* ", [" / "], "arithmetic"),
    (r" / ", [" * "], "arithmetic"),
    (r"\bbreak;", ["continue;"], "break/continue"),
    (r"\bcontinue;", ["break;"], "break/continue"),
    (r"\btrue\b", ["false"], "boolean"),
    (r"\bfalse\b", ["true"], "boolean"),
    (r"\bstd::min\b", ["std::max"], "min/max"),
    (r"\bstd::max\b", ["std::min"], "min/max"),
    (r"!(?=[A-Za-z_(])", [""], "negation dropped"),
]

NUMBER = re.compile(r"(?<![\w.])((?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?)([fFuUlL]*)(?![\w.'])")

DECLARATION = re.compile(
    r"^(?:(?:const|constexpr|static|auto|unsigned|signed|struct|class|enum|using|typename|"
    r"namespace|template|typedef|friend|static_assert|return|case|default|public|private|"
    r"protected|else|do)\b"
    r"|[A-Za-z_][\w:]*(?:<[^;]*>)?[*&]*\s+[*&]*[A-Za-z_]\w*\s*(?:=|\{|;|\(|\[|,))")


def number_mutants(literal, suffix):
    """The literal doubled and halved, as literals of the same kind."""
    is_float = any(ch in literal for ch in ".eE")
    value = float(literal)
    if value == 0.0:
        return []
    out = []
    if is_float:
        for v in (value * 2.0, value / 2.0):
            s = repr(v)
            if "e" in s and "." not in s.split("e")[0]:
                s = s.replace("e", ".0e", 1)
            if "." not in s and "e" not in s:
                s += ".0"
            out.append(s + suffix)
    else:
        whole = int(literal)
        for v in (whole * 2, whole // 2):
            if v != whole:
                out.append(str(v) + suffix)
    return out


def balanced(s):
    return s.count("(") == s.count(")") and s.count("{") == s.count("}")


def generate(text):
    """Every mutant of `text`, in file order, no two giving the same file."""
    mask = code_mask(text)
    lines = text.split("\n")
    mutants = []
    offset = 0
    prev_code = ""  # the last line holding code, stripped
    for index, line in enumerate(lines):
        line_mask = mask[offset:offset + len(line)]
        offset += len(line) + 1
        code = "".join(ch if m else " " for ch, m in zip(line, line_mask))
        if not code.strip():
            continue

        def all_code(start, end, line_mask=line_mask):
            return all(line_mask[start:end])

        for pattern, news, kind in REPLACEMENTS:
            for m in re.finditer(pattern, line):
                if not all_code(m.start(), m.end()):
                    continue
                for new in news:
                    mutants.append(Mutant(index + 1, m.start(), m.group(0), new, kind))
        for m in NUMBER.finditer(line):
            if not all_code(m.start(), m.end()):
                continue
            for new in number_mutants(m.group(1), m.group(2)):
                mutants.append(Mutant(index + 1, m.start(), m.group(0), new, "constant"))
        # A whole simple statement removed: one line, starting a statement, not a declaration.
        stripped = code.strip()
        starts_statement = prev_code == "" or prev_code[-1] in "{};:" or prev_code == "else"
        if (stripped.endswith(";") and starts_statement and balanced(stripped)
                and not DECLARATION.match(stripped)
                and (not stripped.startswith("if") or "{" not in stripped)):
            mutants.append(Mutant(index + 1, 0, line, "", "statement removed"))
        elif stripped == "return;" and starts_statement:
            mutants.append(Mutant(index + 1, 0, line, "", "statement removed"))
        prev_code = stripped
    unique = {}
    for mu in mutants:
        unique.setdefault(apply(text, mu), mu)
    unique.pop(text, None)
    return list(unique.values())


def apply(text, mu):
    lines = text.split("\n")
    line = lines[mu.line - 1]
    if mu.kind == "statement removed":
        lines[mu.line - 1] = ""
    else:
        lines[mu.line - 1] = line[:mu.col] + mu.new + line[mu.col + len(mu.old):]
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------
# The map: FILE: BINARY... (sim preset test targets).


def load_map(path):
    table = {}
    with open(path, encoding="utf-8") as f:
        for raw in f:
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            name, _, binaries = line.partition(":")
            table[name.strip()] = binaries.split()
    return table


# ---------------------------------------------------------------------------------------------
# The scratch copy and its build.


class Scratch:
    def __init__(self, root, jobs, log):
        self.root = root
        self.src = os.path.join(root, "src")
        self.jobs = jobs
        self.log = log

    def sync(self):
        os.makedirs(self.src, exist_ok=True)
        files = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=ROOT,
                               check=True, capture_output=True).stdout.decode().split("\0")
        for rel in files:
            source = os.path.join(ROOT, rel)
            if not rel or not os.path.isfile(source) or os.path.islink(source):
                continue
            target = os.path.join(self.src, rel)
            if os.path.isfile(target) and same_bytes(source, target):
                continue
            os.makedirs(os.path.dirname(target), exist_ok=True)
            # A changed file gets the time of the copy, not its own: an object built in the
            # scratch copy after the file was edited (but from its older text) would otherwise
            # look newer than it, and the build would keep the stale object.
            shutil.copy(source, target)

    def run(self, args, timeout=None):
        with open(self.log, "a", encoding="utf-8") as log:
            log.write("$ " + " ".join(args) + "\n")
            log.flush()
            # Its own process group, all of which a timeout ends: ctest's test processes (a
            # mutant's endless loop) would otherwise outlive ctest and load the machine.
            with subprocess.Popen(args, cwd=self.src, stdout=log, stderr=subprocess.STDOUT,
                                  start_new_session=True) as child:
                try:
                    return child.wait(timeout=timeout)
                except subprocess.TimeoutExpired:
                    try:
                        os.killpg(child.pid, signal.SIGKILL)
                    except ProcessLookupError:
                        pass
                    child.wait()
                    return None

    def configure(self):
        return self.run(["cmake", "--preset", "sim", "-DBOTICELLI_BUILD_BENCH=OFF"]) == 0

    def build(self, binaries, timeout):
        return self.run(["cmake", "--build", "--preset", "sim", "-j", str(self.jobs), "--target"]
                        + binaries, timeout) == 0

    def entries(self, binaries):
        """The binaries' ctest entries (the binary's own, or one per test group)."""
        regex = "^(" + "|".join(re.escape(b) for b in binaries) + ")(_[A-Z][A-Za-z]*)?$"
        listing = subprocess.run(["ctest", "--preset", "sim", "-N", "-R", regex], cwd=self.src,
                                 capture_output=True, text=True).stdout
        return re.findall(r"Test\s+#\d+: (\S+)", listing)

    def test_entry(self, name, timeout_s):
        """'pass', 'fail' or 'timeout' for one ctest entry."""
        out = os.path.join(self.root, "ctest.out")
        args = ["ctest", "--preset", "sim", "--no-tests=error", "-R", "^" + re.escape(name) + "$",
                "--timeout", str(int(timeout_s)), "--output-log", out]
        if os.path.exists(out):
            os.remove(out)
        rc = self.run(args, timeout=timeout_s * 2 + 60)
        text = open(out, encoding="utf-8", errors="replace").read() if os.path.exists(out) else ""
        if rc is None or "***Timeout" in text:
            return "timeout"
        return "pass" if rc == 0 else "fail"

    def test(self, entries):
        """'pass', 'fail' or 'timeout': each (name, timeout) in turn, up to the first that fails.

        The caller orders them cheapest first, so a mutant that a short test group catches does
        not cost the long ones (a whole-mission binary's groups take 20 s to 190 s).
        """
        for name, timeout_s in entries:
            status = self.test_entry(name, timeout_s)
            if status != "pass":
                return status
        return "pass"


def same_bytes(a, b):
    if os.path.getsize(a) != os.path.getsize(b):
        return False
    with open(a, "rb") as fa, open(b, "rb") as fb:
        return fa.read() == fb.read()


# ---------------------------------------------------------------------------------------------


def score_file(scratch, rel, binaries, args):
    result = FileResult(rel, binaries, args.seed)
    start = time.monotonic()
    path = os.path.join(scratch.src, rel)  # the copy that is mutated
    with open(os.path.join(ROOT, rel), encoding="utf-8") as f:
        original = f.read()  # the same as the copy's after the sync
    mutants = generate(original)
    result.generated = len(mutants)
    rng = random.Random(f"{args.seed}:{rel}")
    sample = sorted(rng.sample(mutants, min(args.n, len(mutants))), key=lambda m: (m.line, m.col))
    result.sampled = len(sample)
    if args.list:
        result.mutants = sample
        return result
    if not scratch.build(binaries, args.build_timeout):
        result.error = "the unmutated tree does not build (see the log)"
        return result
    # The unmutated run, one entry at a time: each entry's time orders the mutants' runs
    # (cheapest first) and sets its timeout (3x its unmutated run + 10 s, at least --timeout).
    names = scratch.entries(binaries)
    if not names:
        result.error = "no ctest entry for " + ", ".join(binaries)
        return result
    plan = []
    for name in names:
        t0 = time.monotonic()
        if scratch.test_entry(name, max(args.timeout, 1800)) != "pass":
            result.error = f"{name} fails on the unmutated tree (see the log)"
            return result
        seconds = time.monotonic() - t0
        plan.append((seconds, name, max(args.timeout, 3.0 * seconds + 10.0)))
    plan = [(name, timeout_s) for _, name, timeout_s in sorted(plan)]
    try:
        for index, mu in enumerate(sample):
            if index < args.skip:
                mu.outcome = "not run"
                result.not_run += 1
                continue
            t = time.monotonic()
            with open(path, "w", encoding="utf-8") as f:
                f.write(apply(original, mu))
            if not scratch.build(binaries, args.build_timeout):
                mu.outcome = "not compiling"
                result.not_compiling += 1
            else:
                status = scratch.test(plan)
                mu.outcome = {"fail": "caught", "pass": "survived", "timeout": "timed out"}[status]
                if status == "fail":
                    result.caught += 1
                elif status == "pass":
                    result.survived += 1
                else:
                    result.timed_out += 1
            mu.seconds = round(time.monotonic() - t, 1)
            if not args.json:
                print(f"  {rel}:{mu.line}: {mu.outcome:13} {mu.describe()}", flush=True)
    finally:
        with open(path, "w", encoding="utf-8") as f:
            f.write(original)
    result.mutants = sample
    result.wall_s = round(time.monotonic() - start, 1)
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("files", nargs="+", metavar="FILE", help="a source file, from the top")
    parser.add_argument("--n", type=int, default=30, help="mutants sampled per file (30)")
    parser.add_argument("--seed", type=int, default=1, help="the sample's seed (1)")
    parser.add_argument("--skip", type=int, default=0,
                        help="run only the sample's mutants after its first SKIP (a stopped run's)")
    parser.add_argument("--json", action="store_true", help="print the results as JSON")
    parser.add_argument("--list", action="store_true",
                        help="only list the sampled mutants (no build)")
    parser.add_argument("--timeout", type=float, default=60.0,
                        help="least per-test timeout in seconds; else 3x the unmutated run + 10")
    parser.add_argument("--build-timeout", type=float, default=1800.0)
    parser.add_argument("--jobs", type=int, default=int(os.environ.get("JOBS", "1") or 1))
    parser.add_argument("--scratch", default=os.environ.get("MUTATION_SCRATCH", os.path.join(
        os.environ.get("TMPDIR", "/tmp"), "boticelli-mutation-score")))
    parser.add_argument("--map", default=MAP_FILE)
    args = parser.parse_args()
    if args.skip < 0 or args.skip > args.n:
        parser.error(f"--skip must be within 0..{args.n}")

    table = load_map(args.map)
    for rel in args.files:
        if rel not in table:
            parser.error(f"{rel} has no line in {os.path.relpath(args.map, ROOT)}")
        if not os.path.isfile(os.path.join(ROOT, rel)):
            parser.error(f"no such file: {rel}")
    os.makedirs(args.scratch, exist_ok=True)
    scratch = Scratch(args.scratch, args.jobs, os.path.join(args.scratch, "last.log"))
    open(scratch.log, "w", encoding="utf-8").close()
    started = time.monotonic()
    if not args.list:
        scratch.sync()
    if not args.list and not scratch.configure():
        sys.exit(f"mutation-score: configuring the scratch copy failed (see {scratch.log})")

    results = []
    for rel in args.files:
        if not args.json:
            print(f"{rel}: {', '.join(table[rel])}", flush=True)
        results.append(score_file(scratch, rel, table[rel], args))
    # Leave the scratch build unmutated for the next run.
    if not args.list:
        scratch.build(sorted({b for r in results for b in r.binaries}), args.build_timeout)
    wall = round(time.monotonic() - started, 1)

    if args.json:
        out = {"seed": args.seed, "n": args.n, "wall_s": wall, "files": []}
        for r in results:
            d = asdict(r)
            d["score"] = r.score()
            out["files"].append(d)
        print(json.dumps(out, indent=2))
    elif args.list:
        for r in results:
            print(f"{r.file}: {r.generated} generated, {r.sampled} sampled (seed {r.seed})")
            for mu in r.mutants:
                print(f"  {r.file}:{mu.line}: {mu.describe()}")
    else:
        head = ("file", "generated", "sampled", "caught", "survived", "timed out",
                "not compiling", "not run", "score", "wall s")
        rows = [head]
        for r in results:
            s = r.score()
            rows.append((r.file, r.generated, r.sampled, r.caught, r.survived, r.timed_out,
                         r.not_compiling, r.not_run, "-" if s is None else f"{100 * s:.0f}%", r.wall_s))
        widths = [max(len(str(row[i])) for row in rows) for i in range(len(head))]
        print()
        for row in rows:
            print("  ".join(str(v).ljust(w) for v, w in zip(row, widths)).rstrip())
        for r in results:
            if r.error:
                print(f"{r.file}: {r.error}")
            for mu in r.mutants:
                if mu.outcome == "survived":
                    print(f"survived  {r.file}:{mu.line}: {mu.describe()}")
        print(f"seed {args.seed}, n {args.n}, wall time {wall} s")
    sys.exit(1 if any(r.error for r in results) else 0)


if __name__ == "__main__":
    main()
