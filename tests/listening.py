"""Which addresses processes listen on, as `ss` reports them: every listening TCP socket and every
bound UDP socket, with the process that holds it."""
import collections
import ipaddress
import os
import re
import subprocess

import psutil

Listening = collections.namedtuple('Listening', 'program pid protocol address')
WILDCARD = 'wildcard'


def program(cmdline):
    """The program a command line runs: the script for a Python interpreter."""
    words = [os.path.basename(word) for word in cmdline]
    if words and words[0].startswith('python'):
        words = [word for word in words[1:] if not word.startswith('-')]
    return words[0] if words else '?'


def parse_address(local):
    """The address of an ss local column ('0.0.0.0:5', '[::ffff:10.0.0.1]:5', '*:5'), IPv4-mapped
    addresses as IPv4, WILDCARD for any address."""
    host = local.rsplit(':', 1)[0].strip('[]').split('%')[0]
    if host == '*':
        return WILDCARD
    address = ipaddress.ip_address(host)
    address = getattr(address, 'ipv4_mapped', None) or address
    return WILDCARD if address.is_unspecified else str(address)


def listening_sockets(netns=None):
    """Every Listening socket of the network namespace `netns` (this process's if None)."""
    command = ['ss', '-H', '-l', '-n', '-p', '-t', '-u']
    if netns:
        command = ['ip', 'netns', 'exec', netns] + command
    output = subprocess.run(command, capture_output=True, text=True, check=True,
                            timeout=30).stdout
    sockets = []
    for line in output.splitlines():
        fields = line.split()
        if len(fields) < 5:
            continue
        for pid in map(int, re.findall(r'pid=(\d+)', line)):
            try:
                name = program(psutil.Process(pid).cmdline())
            except psutil.NoSuchProcess:
                continue
            sockets.append(Listening(name, pid, fields[0], parse_address(fields[4])))
    return sockets


def process_tree(pid):
    """pid and the pids of its descendants still running."""
    try:
        return {pid} | {child.pid for child in psutil.Process(pid).children(recursive=True)}
    except psutil.NoSuchProcess:
        return set()
