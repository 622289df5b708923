"""Note scripts (docs/scores.md) read in pure Python, and toonray's piano key timing.

This module does not import bpy, so it runs (and is tested) in any Python 3.7+.

The reader follows toonray's own parser (src/toonray/score/note_script.cpp) line for line:
the seed format (one line per eighth note, ``E:w26,w28|H:w16``, ``Empty``) and the whole
extension (``#`` comments, S/T/X, dots, ``+`` ties, tick durations, ``m`` keys, ``@velocity``,
and the directives ppq, tempo, time, step, wait, velocity, track, channel, pedal). Times come
out in seconds exactly as toonray computes them (tempo in whole microseconds per quarter, the
same floating-point operations). What it does not read: Standard MIDI Files -- convert them
first with ``toonray score convert song.mid song.notes``.

The key timing is toonray's ``PianoPlayback`` (src/toonray/piano/piano_animation.cpp,
docs/piano.md): a key starts down ``attack`` = 15 ms before the onset, is fully down at the
onset, holds at least ``min_hold`` = 1/24 s, rises over ``release`` = 25 ms from the note's end,
and a repeated key is fully up for ``min_up`` = 1/24 s before its next press begins.
"""

import bisect
import math

DEFAULT_PPQ = 384
DEFAULT_TEMPO_US = 833333  # 72 quarter notes per minute
MIDI_DEFAULT_TEMPO_US = 500000
DEFAULT_VELOCITY = 80
MAX_TRACK = 1023
MAX_TICK = 1 << 52
MAX_TICKS_TERM = 0x7FFFFFFF
MAX_DOTS = 3
LETTERS = (("W", 1), ("H", 2), ("Q", 4), ("E", 8), ("S", 16), ("T", 32), ("X", 64))

LOWEST_KEY = 21   # A0
HIGHEST_KEY = 108  # C8


class NoteScriptError(Exception):
    """A bad note script: the message is 'file:line: reason', as toonray's."""


# ---- keys -----------------------------------------------------------------------------------

def is_black_key(midi):
    return midi % 12 in (1, 3, 6, 8, 10)


def _key_tables():
    white, black, names = [None], [None], {}
    for midi in range(LOWEST_KEY, HIGHEST_KEY + 1):
        if is_black_key(midi):
            black.append(midi)
            names[midi] = "b%d" % (len(black) - 1)
        else:
            white.append(midi)
            names[midi] = "w%d" % (len(white) - 1)
    return white, black, names


_WHITE, _BLACK, _NAMES = _key_tables()
assert _WHITE[1] == 21 and _BLACK[1] == 22 and _WHITE[24] == 60 and _WHITE[52] == 108


def white_key(n):
    """MIDI note of white key wN (1..52), or -1."""
    return _WHITE[n] if 1 <= n <= 52 else -1


def black_key(n):
    """MIDI note of black key bN (1..36), or -1."""
    return _BLACK[n] if 1 <= n <= 36 else -1


def key_name(midi):
    """'w24' for MIDI 60, 'b17' for 61, ...; 'mN' off the piano."""
    return _NAMES.get(midi, "m%d" % midi)


def key_names():
    """All 88 key names, from A0 up."""
    return [_NAMES[m] for m in range(LOWEST_KEY, HIGHEST_KEY + 1)]


# ---- the score ------------------------------------------------------------------------------

class Note:
    __slots__ = ("start", "end", "key", "velocity", "track", "channel")

    def __init__(self, start, end, key, velocity, track=0, channel=0):
        self.start, self.end, self.key = start, end, key
        self.velocity, self.track, self.channel = velocity, track, channel

    def __repr__(self):
        return "Note(%r, %r, %s, %d)" % (self.start, self.end, key_name(self.key), self.velocity)


class Score:
    """A parsed note script: notes in ticks and in seconds, the tempo map, warnings."""

    def __init__(self):
        self.ppq = DEFAULT_PPQ
        self.tempo = []        # [(tick, us per quarter)], normalized: sorted, one per tick, tick 0 first
        self.time_signatures = []
        self.pedal = []        # [(tick, value, track, channel)]
        self.notes = []        # Note in ticks, normalized (overlaps cut, sorted by start, key)
        self.end_tick = 0
        self.warnings = []

    def seconds_at(self, tick):
        """Seconds at a tick through the tempo map (toonray's TempoMap, same operations)."""
        seconds = 0.0
        for i, (t, us) in enumerate(self.tempo):
            nxt = self.tempo[i + 1][0] if i + 1 < len(self.tempo) else None
            if nxt is None or tick < nxt:
                return seconds + _span(t, tick, us, self.ppq)
            seconds += _span(t, nxt, us, self.ppq)
        return _span(0, tick, MIDI_DEFAULT_TEMPO_US, self.ppq)  # no tempo at all

    def notes_in_seconds(self):
        """[(start s, end s, midi key, velocity)] sorted by start, then key."""
        out = [(self.seconds_at(n.start), self.seconds_at(n.end), n.key, n.velocity)
               for n in self.notes]
        out.sort(key=lambda n: (n[0], n[2]))
        return out

    def end_time(self):
        """End of the piece in seconds (the end of the last line or note)."""
        return self.seconds_at(self.end_tick)


def _span(from_tick, to_tick, us, ppq):
    # static_cast<double>(to - from) * us * 1e-6 / ppq, evaluated left to right as in C++.
    return float(to_tick - from_tick) * us * 1e-6 / ppq


def _letter_ticks(per_whole, dots, ppq):
    num = 4 * ppq * ((2 << dots) - 1)
    den = per_whole << dots
    return num // den if num % den == 0 else 0


def _tempo_from_bpm(bpm):
    us = math.floor(60e6 / bpm + 0.5)  # std::round: halves away from zero (bpm > 0 here)
    return int(us) if 1 <= us <= 0xFFFFFF else 0


def _is_digits(s):
    return bool(s) and all("0" <= c <= "9" for c in s)


def _parse_int(s):
    """A whole number written with digits only (as std::from_chars), else None."""
    return int(s) if _is_digits(s) else None


_SPACE = " \t\r\f\v"


def _trim(s):
    return s.strip(_SPACE)


class _Parser:
    def __init__(self, file, default_tempo_us):
        self.file = file
        self.line_no = 0
        self.score = Score()
        self.score.tempo.append((0, default_tempo_us))
        self.default_tempo_us = default_tempo_us
        self.started = False
        self.step_ticks = 0
        self.velocity = DEFAULT_VELOCITY
        self.track = 0
        self.channel = 0
        self.cursors = {}

    def fail(self, message):
        raise NoteScriptError("%s:%d: %s" % (self.file, self.line_no, message))

    # cursor of the current voice
    def cursor(self):
        return self.cursors.setdefault((self.track, self.channel), 0)

    def advance(self, ticks):
        c = self.cursor()
        if ticks > MAX_TICK - c:
            self.fail("the score runs past the longest supported time")
        self.cursors[(self.track, self.channel)] = c + ticks

    def step(self):
        if self.step_ticks > 0:
            return self.step_ticks
        if self.score.ppq % 2 != 0:
            self.fail("a line is an eighth note by default, which is not a whole number of ticks "
                      "at ppq %d; set 'step'" % self.score.ppq)
        return self.score.ppq // 2

    def parse(self, text):
        if text.startswith("\ufeff"):
            text = text[1:]
        for raw in text.split("\n"):
            self.line_no += 1
            line = raw.split("#", 1)[0]
            line = _trim(line)
            if line:
                self.parse_line(line)
        score = self.score
        for tick in self.cursors.values():
            score.end_tick = max(score.end_tick, tick)
        _normalize(score, self.default_tempo_us, self.file)
        return score

    def parse_line(self, line):
        end = len(line)
        for i, c in enumerate(line):
            if c in " \t\f\v\r:":
                end = i
                break
        word = line[:end]
        rest = _trim(line[end:])
        lower_word = all("a" <= c <= "z" for c in word)

        if word == "ppq":
            if self.started:
                self.fail("'ppq' must come before every other line")
            self.score.ppq = self.int_argument(word, rest, 1, 0x7FFF)
            self.started = True
            return
        self.started = True
        if line.lower() == "empty":
            self.advance(self.step())
        elif lower_word and word and (not rest or rest[0] != ":"):
            self.directive(word, rest)
        elif word.lower() == "empty":
            self.fail("'Empty' takes nothing after it")
        else:
            self.note_line(line)

    def int_argument(self, directive, arg, lo, hi):
        if not arg:
            self.fail("'%s' needs a number" % directive)
        if " " in arg or "\t" in arg:
            self.fail("'%s' takes one value, got '%s'" % (directive, arg))
        v = _parse_int(arg)
        if v is None or v < lo or v > hi:
            self.fail("bad value '%s' for '%s': expected a whole number from %d to %d"
                      % (arg, directive, lo, hi))
        return v

    def one_argument(self, directive, arg):
        if not arg:
            self.fail("'%s' needs a value" % directive)
        if " " in arg or "\t" in arg:
            self.fail("'%s' takes one value, got '%s'" % (directive, arg))

    def directive(self, word, arg):
        score = self.score
        if word == "tempo":
            self.one_argument(word, arg)
            score.tempo.append((self.cursor(), self.parse_tempo(arg)))
        elif word == "time":
            self.one_argument(word, arg)
            num = den = None
            if "/" in arg:
                a, b = arg.split("/", 1)
                num, den = _parse_int(a), _parse_int(b)
            if num is None or den is None:
                self.fail("bad time signature '%s': expected N/D such as 2/4" % arg)
            if num < 1 or num > 255 or den < 1 or den > 128 or (den & (den - 1)) != 0:
                self.fail("bad time signature '%s': N is 1..255 and D a power of two from 1 to 128"
                          % arg)
            score.time_signatures.append((self.cursor(), num, den))
        elif word == "step":
            self.one_argument(word, arg)
            self.step_ticks = self.duration(arg)
        elif word == "wait":
            self.one_argument(word, arg)
            self.advance(self.duration(arg))
        elif word == "velocity":
            self.velocity = self.int_argument(word, arg, 1, 127)
        elif word == "track":
            self.track = self.int_argument(word, arg, 0, MAX_TRACK)
        elif word == "channel":
            self.channel = self.int_argument(word, arg, 1, 16) - 1
        elif word == "pedal":
            if arg == "down":
                value = 127
            elif arg == "up":
                value = 0
            else:
                value = _parse_int(arg)
                if value is None or value > 127:
                    self.fail("bad pedal value '%s': expected down, up or 0..127" % arg)
            score.pedal.append((self.cursor(), value, self.track, self.channel))
        elif word == "ppq":
            self.fail("'ppq' must come before every other line")
        else:
            self.fail("unknown directive '%s' (known: ppq, tempo, time, step, wait, velocity, "
                      "track, channel, pedal)" % word)

    def parse_tempo(self, arg):
        if len(arg) > 2 and arg.endswith("us"):
            us = _parse_int(arg[:-2])
            if us is None or us < 1 or us > 0xFFFFFF:
                self.fail("bad tempo '%s': microseconds per quarter are 1..16777215" % arg)
            return us
        bpm = None
        # std::from_chars(double): digits, optional fraction and exponent; no sign, no spaces.
        if arg and (arg[0].isdigit() or arg[0] == ".") and all(c in "0123456789.eE+-" for c in arg):
            try:
                bpm = float(arg)
            except ValueError:
                bpm = None
        if bpm is None or not math.isfinite(bpm) or not bpm > 0:
            self.fail("bad tempo '%s': expected quarter notes per minute (such as 72) or "
                      "microseconds per quarter (such as 833333us)" % arg)
        us = _tempo_from_bpm(bpm)
        if us == 0:
            self.fail("tempo %s is out of range (3.58 to 60000000 bpm)" % arg)
        return us

    def duration(self, text):
        if not text:
            self.fail("missing duration")
        total = 0
        for term in text.split("+"):
            term = _trim(term)
            if not term:
                self.fail("malformed duration '%s'" % text)
            if "0" <= term[0] <= "9":
                ticks = _parse_int(term)
                if ticks is None or ticks < 1 or ticks > MAX_TICKS_TERM:
                    self.fail("bad duration '%s': ticks are 1..%d" % (term, MAX_TICKS_TERM))
            else:
                per_whole = dict(LETTERS).get(term[0])
                dots = term[1:]
                if per_whole is None or dots.strip(".") != "":
                    self.fail("unknown duration '%s' (use W, H, Q, E, S, T or X for whole to 64th "
                              "notes, dots as in 'Q.', '+' to tie, or ticks)" % term)
                if len(dots) > MAX_DOTS:
                    self.fail("too many dots in '%s' (at most %d)" % (term, MAX_DOTS))
                ticks = _letter_ticks(per_whole, len(dots), self.score.ppq)
                if ticks == 0:
                    self.fail("duration '%s' is not a whole number of ticks at ppq %d"
                              % (term, self.score.ppq))
            total += ticks
            if total > MAX_TICK:
                self.fail("duration '%s' is too long" % text)
        return total

    def key(self, token):
        kind = token[:1]
        numbered = kind in ("w", "b", "m") and len(token) > 1 and _is_digits(token[1:])
        if not numbered:
            self.fail("unknown key '%s' (keys are w1..w52, b1..b36 or m0..m127)" % token)
        n = int(token[1:]) if len(token) <= 11 else -1
        if kind == "w":
            midi = white_key(n)
            if midi < 0:
                self.fail("unknown key '%s': white keys are w1..w52" % token)
            return midi
        if kind == "b":
            midi = black_key(n)
            if midi < 0:
                self.fail("unknown key '%s': black keys are b1..b36" % token)
            return midi
        if n < 0 or n > 127:
            self.fail("unknown key '%s': MIDI keys are m0..m127" % token)
        return n

    def note_line(self, line):
        start = self.cursor()
        for group in line.split("|"):
            group = _trim(group)
            if not group:
                self.fail("empty note group in '%s'" % line)
            if ":" not in group:
                self.fail("malformed note group '%s': expected DURATION:KEYS such as "
                          "'E:w26,w28,w30'" % group)
            dur_text, keys = group.split(":", 1)
            length = self.duration(_trim(dur_text))
            if length > MAX_TICK - start:
                self.fail("the score runs past the longest supported time")
            keys = _trim(keys)
            if not keys:
                self.fail("no keys after ':' in '%s'" % group)
            for token in keys.split(","):
                token = _trim(token)
                if not token:
                    self.fail("missing key in '%s'" % group)
                velocity = self.velocity
                if "@" in token:
                    token, v = token.split("@", 1)
                    v = _parse_int(_trim(v))
                    if v is None or v < 1 or v > 127:
                        self.fail("bad velocity in '%s': expected 1..127 after '@'" % token)
                    velocity = v
                    token = _trim(token)
                self.score.notes.append(Note(start, start + length, self.key(token), velocity,
                                             self.track, self.channel))
        self.advance(self.step())


def _sort_last_wins(items):
    items = sorted(items, key=lambda x: x[0])  # stable: file order within a tick
    out = []
    for x in items:
        if out and out[-1][0] == x[0]:
            out[-1] = x
        else:
            out.append(x)
    return out


def _normalize(score, default_tempo_us, file):
    score.tempo = _sort_last_wins(score.tempo)
    if not score.tempo or score.tempo[0][0] != 0:
        score.tempo.insert(0, (0, default_tempo_us))
    score.time_signatures = _sort_last_wins(score.time_signatures)
    score.pedal.sort(key=lambda p: (p[0], p[2], p[3]))
    notes = sorted(score.notes, key=lambda n: (n.track, n.channel, n.key, n.start, n.end, n.velocity))
    zero_length = sum(1 for n in notes if n.end <= n.start)
    shortened = 0
    for a, b in zip(notes, notes[1:]):
        if a.track == b.track and a.channel == b.channel and a.key == b.key and b.start < a.end:
            a.end = b.start
            shortened += 1
    notes = [n for n in notes if n.end > n.start]
    notes.sort(key=lambda n: (n.start, n.key, n.track, n.channel, n.end, n.velocity))
    score.notes = notes
    for n in notes:
        score.end_tick = max(score.end_tick, n.end)
    for p in score.pedal:
        score.end_tick = max(score.end_tick, p[0])
    for t in score.tempo:
        score.end_tick = max(score.end_tick, t[0])
    for t in score.time_signatures:
        score.end_tick = max(score.end_tick, t[0])
    if shortened:
        score.warnings.append("%s: %d note(s) overlapped a later note of the same key on the same "
                              "track and channel and were cut short where it starts"
                              % (file, shortened))
    if zero_length:
        score.warnings.append("%s: %d note(s) of zero length dropped" % (file, zero_length))


def parse_note_script(text, file="<notes>", default_tempo_bpm=None):
    """Parses a note script; raises NoteScriptError('file:line: reason') on the first bad line.

    ``default_tempo_bpm`` replaces the default 72 quarter notes per minute (used until the
    script's first ``tempo`` line, as toonray's 72 would be)."""
    default_us = DEFAULT_TEMPO_US
    if default_tempo_bpm:
        default_us = _tempo_from_bpm(float(default_tempo_bpm))
        if default_us == 0:
            raise NoteScriptError("%s: tempo %s is out of range (3.58 to 60000000 bpm)"
                                  % (file, default_tempo_bpm))
    return _Parser(file, default_us).parse(text)


def load_note_script(path, default_tempo_bpm=None):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"MThd":
        raise NoteScriptError(
            "%s: this is a Standard MIDI File; the add-on reads note scripts only: convert it with "
            "'toonray score convert %s song.notes'" % (path, path))
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise NoteScriptError("%s: not UTF-8 text (byte %d)" % (path, e.start))
    return parse_note_script(text, path, default_tempo_bpm)


# ---- toonray's key playback ---------------------------------------------------------------

class PlaybackSettings:
    def __init__(self, attack=0.015, release=0.025, min_hold=1.0 / 24.0, min_up=1.0 / 24.0):
        self.attack, self.release, self.min_hold, self.min_up = attack, release, min_hold, min_up


class KeyPress:
    __slots__ = ("on", "off", "start_depth")

    def __init__(self, on, off, start_depth=0.0):
        self.on, self.off, self.start_depth = on, off, start_depth

    def __repr__(self):
        return "KeyPress(on=%r, off=%r, start_depth=%r)" % (self.on, self.off, self.start_depth)


class KeyPlayback:
    """toonray's PianoPlayback for the keys: per key, presses after the merge, repeated-note and
    minimum-hold rules; ``depth(midi, t)`` is 0 at rest and 1 fully pressed."""

    def __init__(self, notes_seconds, settings=None):
        s = self.settings = settings or PlaybackSettings()
        if not (s.attack > 0 and s.release > 0 and s.min_hold >= 0 and s.min_up >= 0):
            raise ValueError("attack and release must be positive, min_hold and min_up not negative")
        self.ignored = 0
        lists = {}
        for start, end, key, _velocity in notes_seconds:
            if key < LOWEST_KEY or key > HIGHEST_KEY or not (math.isfinite(start) and math.isfinite(end)):
                self.ignored += 1
                continue
            lists.setdefault(key, []).append(KeyPress(start, max(start, end)))
        self.presses = {}
        for key, presses in lists.items():
            presses.sort(key=lambda p: (p.on, -p.off))
            merged = []
            for p in presses:
                if merged and p.on - merged[-1].on < 1e-6:
                    merged[-1].off = max(merged[-1].off, p.off)
                    continue
                merged.append(p)
            for a, b in zip(merged, merged[1:]):
                a.off = min(a.off, b.on - s.attack - s.release - s.min_up)
            for p in merged:
                p.off = max(p.off, p.on + s.min_hold)
            for i in range(1, len(merged)):
                merged[i].start_depth = self._press_depth(merged[i - 1], merged[i].on - s.attack)
            self.presses[key] = merged
        self._begins = {k: [p.on - s.attack for p in v] for k, v in self.presses.items()}

    def _press_depth(self, p, t):
        s = self.settings
        begin = p.on - s.attack
        if t < begin:
            return 0.0
        down = min(1.0, p.start_depth + (min(t, p.off) - begin) / s.attack)
        if t <= p.off:
            return down
        return max(0.0, down - (t - p.off) / s.release)

    def depth(self, midi, t):
        presses = self.presses.get(midi)
        if not presses:
            return 0.0
        # The latest press that has begun decides (it started from where the previous one got to).
        i = bisect.bisect_right(self._begins[midi], t)
        return 0.0 if i == 0 else self._press_depth(presses[i - 1], t)

    def breakpoints(self, midi):
        """The key's depth curve as [(t, depth)] corners: linear between them, constant
        outside. Evaluating it with linear interpolation gives exactly ``depth(midi, t)``."""
        s = self.settings
        presses = self.presses.get(midi, [])
        points = []
        for i, p in enumerate(presses):
            begin = p.on - s.attack
            corners = [(begin, p.start_depth)]
            reach = begin + (1.0 - p.start_depth) * s.attack  # fully down (<= onset)
            corners.append((reach, 1.0))
            corners.append((p.off, 1.0))
            corners.append((p.off + s.release, 0.0))
            nxt = presses[i + 1].on - s.attack if i + 1 < len(presses) else None
            for t, d in corners:
                if nxt is not None and t >= nxt:
                    break  # the next press takes over from where this one got to
                if points and t <= points[-1][0] + 1e-12:
                    points[-1] = (points[-1][0], d)
                    continue
                points.append((t, d))
        return points

    def active_span(self, midi):
        """(first time the key moves, time it is last back up), or None."""
        presses = self.presses.get(midi)
        if not presses:
            return None
        return presses[0].on - self.settings.attack, presses[-1].off + self.settings.release
