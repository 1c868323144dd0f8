"""The folders of a page, one module per folder (controls, readouts, torsors and energy,
precision and cost, lesson, X–Y plot, parameter study, polar diagram, cycle, class board,
challenge, display, join...), and the pure tables and data they show. A panel is handed
what it shows and a way to send requests; it never steps the simulation.
"""
