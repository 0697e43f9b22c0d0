/PROG  TOUCHES
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "tcpcal touches";
PROG_SIZE	= 0;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 8;
MEMORY_SIZE	= 0;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,1,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/MN
   1:  !tcpcal touches, 6 points ;
   2:J P[1] 10% FINE ;
   3:J P[2] 10% FINE ;
   4:J P[3] 10% FINE ;
   5:J P[4] 10% FINE ;
   6:J P[5] 10% FINE ;
   7:J P[6] 10% FINE ;
   8:J P[7] 10% FINE ;
/POS
P[1:"touch 1"]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =    815.103  mm,	Y =   -161.836  mm,	Z =    560.115  mm,
	W =    180.000 deg,	P =       .000 deg,	R =      0.000 deg
   GP2:
	UF : 0, UT : 1,
	J1 =    45.000 deg,	J2 =      0.000 deg
};
P[2:"touch 2"]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =    880.280  mm,	Y =   -133.007  mm,	Z =    575.374  mm,
	W =    170.000 deg,	P =     20.000 deg,	R =     30.000 deg
   GP2:
	UF : 0, UT : 1,
	J1 =    45.000 deg,	J2 =      0.000 deg
};
P[3:"touch 3"]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =    814.777  mm,	Y =      0.673  mm,	Z =    496.825  mm,
	W =    160.000 deg,	P =    -25.000 deg,	R =    -40.000 deg
   GP2:
	UF : 0, UT : 1,
	J1 =    45.000 deg,	J2 =      0.000 deg
};
P[4:"touch 4"]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =    948.359  mm,	Y =   -121.185  mm,	Z =    569.725  mm,
	W =   -170.000 deg,	P =     30.000 deg,	R =     90.000 deg
   GP2:
	UF : 0, UT : 1,
	J1 =    45.000 deg,	J2 =      0.000 deg
};
P[5:"touch 5"]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =    989.502  mm,	Y =   -317.762  mm,	Z =    473.475  mm,
	W =    175.000 deg,	P =    -35.000 deg,	R =    120.000 deg
   GP2:
	UF : 0, UT : 1,
	J1 =    45.000 deg,	J2 =      0.000 deg
};
P[6:"touch 6"]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =    999.065  mm,	Y =   -133.594  mm,	Z =    553.420  mm,
	W =    150.000 deg,	P =     15.000 deg,	R =   -100.000 deg
   GP2:
	UF : 0, UT : 1,
	J1 =    45.000 deg,	J2 =      0.000 deg
};
P[7:"home"]{
   GP1:
	UF : 0, UT : 0,
	J1=      0.000 deg,	J2=    -30.000 deg,	J3=     15.000 deg,
	J4=      0.000 deg,	J5=    -75.000 deg,	J6=     90.000 deg
   GP2:
	UF : 0, UT : 1,
	J1 =     0.000 deg,	J2 =      0.000 deg
};
/END
