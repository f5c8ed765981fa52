"""Bounds on what one conversion may take, so that a careless file (a macro that calls itself
without end, one that doubles itself 30 times, an include of a 1 GB file, a FIFO or a device)
ends with an error naming the limit instead of running until memory is gone. Each is far above
what a real robot needs: the book's Baxter converts from 33 kB of xacro into about 700 elements,
nesting macros 3 deep.

PyPI's xacro splices a macro's expansion into its parent one node at a time, each insertion
searching the parent's children (minidom's insertBefore), so its time grows as the square of a
parent's size. replace_node below makes the same change as one splice of the parent's child list,
so that the time grows with the output and the element limit is reached in seconds."""
import errno
import functools
import os
import resource
import stat
import sys
import xml.dom.minidom

import xacro

MAX_FILE_BYTES = 16 * 2 ** 20      # one file read: the input, an include, a YAML file
MAX_NESTING = 100                  # macro calls within macro calls; includes within includes
MAX_ELEMENTS = 100000              # elements evaluated, expansions of macros counted each time
MAX_VALUE_CHARS = 16 * 2 ** 20     # the text one ${...} or $(...) evaluates to
MAX_MEMORY_BYTES = 4 * 2 ** 30     # the process's address space

_elements_evaluated = 0


def _mib(n):
    return '%d MiB' % (n // 2 ** 20)


def _file_type(mode):
    for test, name in ((stat.S_ISDIR, 'a directory'), (stat.S_ISFIFO, 'a FIFO'),
                       (stat.S_ISCHR, 'a character device'), (stat.S_ISBLK, 'a block device'),
                       (stat.S_ISSOCK, 'a socket')):
        if test(mode):
            return name
    return 'a special file'


def checked_open(file, mode='r', *args, **kwargs):
    """open() for xacro's module: a file it reads must be a regular file of at most MAX_FILE_BYTES,
    told by its type and size before it is opened (a FIFO's open waits for a writer, /dev/zero
    never ends). Refusals are OSErrors, which xacro reports as "reason: file" (and an
    optional="true" include skips, as a missing one)."""
    if not any(flag in mode for flag in 'wax+') and not isinstance(file, int):
        info = os.stat(file)
        if not stat.S_ISREG(info.st_mode):
            raise OSError(errno.EINVAL, 'it is %s, not a regular file: xacro reads regular files '
                          'only' % _file_type(info.st_mode), str(file))
        if info.st_size > MAX_FILE_BYTES:
            raise OSError(errno.EFBIG, 'the file has %d bytes, past the limit of %s (%d bytes) '
                          'xacro reads from one file' % (info.st_size, _mib(MAX_FILE_BYTES),
                                                         MAX_FILE_BYTES), str(file))
    return open(file, mode, *args, **kwargs)


def _past_limit(what, hint):
    return xacro.XacroException('%s (%s)' % (what, hint))


def _out_of_memory():
    return _past_limit('out of memory at the limit of %d GiB of address space'
                       % (MAX_MEMORY_BYTES // 2 ** 30), 'a value or an expansion too large?')


def _counted_eval_all(original):
    @functools.wraps(original)
    def eval_all(node, macros, symbols):
        global _elements_evaluated
        _elements_evaluated += 1
        if _elements_evaluated > MAX_ELEMENTS:
            raise _past_limit('more elements than the limit of %d' % MAX_ELEMENTS,
                              'a macro that expands itself many times over?')
        try:
            return original(node, macros, symbols)
        except MemoryError:
            raise _out_of_memory()
    return eval_all


def _nesting_macro_call(original):
    @functools.wraps(original)
    def handle_macro_call(node, macros, symbols):
        if len(xacro.macrostack) >= MAX_NESTING and node.tagName.startswith('xacro:'):
            raise _past_limit('macro calls nested deeper than the limit of %d' % MAX_NESTING,
                              'a macro that calls itself without end?')
        return original(node, macros, symbols)
    return handle_macro_call


def _nesting_parse(original):
    @functools.wraps(original)
    def parse(inp, filename=None):
        if inp is None and len(xacro.filestack) > MAX_NESTING:
            raise _past_limit('includes nested deeper than the limit of %d' % MAX_NESTING,
                              'a file that includes itself?')
        return original(inp, filename)
    return parse


def _bounded_eval_text(original):
    @functools.wraps(original)
    def eval_text(text, symbols):
        try:
            value = original(text, symbols)
        except xacro.XacroException as e:
            if isinstance(e.exc, MemoryError):
                raise _out_of_memory() from e
            raise
        if isinstance(value, str) and len(value) > MAX_VALUE_CHARS:
            raise _past_limit('a value of %d characters, past the limit of %d' % (
                len(value), MAX_VALUE_CHARS), 'from "%s"' % text[:80])
        return value
    return eval_text


def replace_node(node, by, content_only=False):
    """xacro's replace_node (node replaced by `by`, a node or a list of them, or by their children
    when content_only; None: removed) as one splice of the parent's children."""
    parent = node.parentNode
    moved = []
    for doc in [] if by is None else by if isinstance(by, list) else [by]:
        if content_only:
            moved.extend(doc.childNodes)
            del doc.childNodes[:]
        elif doc is not node:
            if doc.parentNode is not None:
                doc.parentNode.removeChild(doc)
            moved.append(doc)
    children = parent.childNodes
    index = children.index(node)
    children[index:index + 1] = moved
    before = children[index - 1] if index else None
    end = index + len(moved)
    after = children[end] if end < len(children) else None
    previous = before
    for child in moved + [after]:
        if child is not None:
            child.previousSibling = previous
        if previous is not None:
            previous.nextSibling = child
        previous = child
    for child in moved:
        child.parentNode = parent
    node.parentNode = node.previousSibling = node.nextSibling = None
    xml.dom.minidom._clear_id_cache(parent)


def apply_limits():
    """Installs the limits in PyPI's xacro (its functions looked up by name at each call)."""
    global _elements_evaluated
    _elements_evaluated = 0
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 50 * MAX_NESTING + 1000))
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    if hard == resource.RLIM_INFINITY or hard > MAX_MEMORY_BYTES:
        if soft == resource.RLIM_INFINITY or soft > MAX_MEMORY_BYTES:
            resource.setrlimit(resource.RLIMIT_AS, (MAX_MEMORY_BYTES, hard))
    xacro.open = checked_open
    xacro.eval_all = _counted_eval_all(xacro.eval_all)
    xacro.handle_macro_call = _nesting_macro_call(xacro.handle_macro_call)
    xacro.parse = _nesting_parse(xacro.parse)
    xacro.eval_text = _bounded_eval_text(xacro.eval_text)
    xacro.replace_node = replace_node
