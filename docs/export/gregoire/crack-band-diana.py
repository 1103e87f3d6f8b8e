# fracid export: DIANA total strain crack model (Python commands of DIANA 10.x)
# source: /work/main/docs/export/gregoire/crack-band-result.json (fracid identify cb.toml --workers 1 --quiet, 2026-11-28T21:40:57+00:00, fracid 0.1.0)
# model: crack-band (crack-band-hordijk); identification status: converged
#   E = 36250 MPa (fixed)
#   nu = 0.2 (fixed)
#   ft = 3.61557 MPa (identified, std 0.137)
#   Gf = 0.069749 N/mm (identified, std 0.00279)
#   c1 = 3 (fixed)
#   c2 = 6.93 (fixed)
# law: the hordijk law at the identified parameters, sampled at 101 openings
#   strength 3.61557 +- 0.14 MPa, fracture energy (area of the table) 0.0697693 +- 0.0028 N/mm, last opening 0.0990812 mm
#   (+- one std, the identification's covariance carried to the law by linearisation)
# units: N-mm-MPa (force N, length mm, stress MPa); every value of the model using this file must be in the same system
# the std are the identification's (from its covariance C); the tables are at the estimate
# tension softening: the same law: DIANA's HORDYK curve at the table's strength and fracture energy is within 0.06% of ft of it
# crack band width: DIANA's own rule from the element (CBSPEC); fracid's crack band scales the law by the element's width across the crack. 'ROTS' is the only CBSPEC value confirmed (seen in working scripts); set the rule your mesh needs
# compression, density and Poisson reduction: not identified by fracid; set them (e.g. COMPRS/COMCRV PARABO with COMSTR and GC, seen in working scripts)
addMaterial( "FRACID_CONCRETE", "CONCR", "TSCR", [] )
setParameter( MATERIAL, "FRACID_CONCRETE", "LINEAR/ELASTI/YOUNG", 36250 )
setParameter( MATERIAL, "FRACID_CONCRETE", "LINEAR/ELASTI/POISON", 0.2 )
setParameter( MATERIAL, "FRACID_CONCRETE", "MODTYP/TOTCRK", "ROTATE" )
setParameter( MATERIAL, "FRACID_CONCRETE", "TENSIL/TENCRV", "HORDYK" )
setParameter( MATERIAL, "FRACID_CONCRETE", "TENSIL/TENSTR", 3.61556722996 )
setParameter( MATERIAL, "FRACID_CONCRETE", "TENSIL/GF1", 0.0697693427807 )
# setParameter( MATERIAL, "FRACID_CONCRETE", "TENSIL/CBSPEC", "ROTS" )
# the same in a .dat file's MATERIALS table (DIANA 10.x style, as written by working input writers):
#   1 NAME "FRACID_CONCRETE"
#     MCNAME CONCR
#     MATMDL TSCR
#     YOUNG  36250
#     POISON 0.2
#     TOTCRK ROTATE
#     TENCRV HORDYK
#     TENSTR 3.61556722996
#     GF1    0.0697693427807
