"""Serving the pages: the viser server and its sessions, start-up, the teacher's class and
its board, follow mode, the network rules (handshakes, addresses students type), and
several worker processes behind one port.
"""
