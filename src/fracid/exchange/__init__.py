"""fracid's results and models taken to other tools: an identification's parameters exported as material input
for finite-element codes (Abaqus, DIANA, a plain table of the traction-separation law), and the configuration's
forward operator served with its exact sensitivities over UM-Bridge.

On the floor of the configuration (it reads results and configurations); only the command imports it.
"""
