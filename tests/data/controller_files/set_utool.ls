/PROG  SET_UTOOL2
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "weld torch";
PROG_SIZE	= 612;
CREATE		= DATE 24-03-11  TIME 10:02:14;
MODIFIED	= DATE 24-03-11  TIME 10:05:40;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 3;
MEMORY_SIZE	= 960;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/MN
   1:  !set the torch frame ;
   2:  PR[60:torch]=P[1] ;
   3:  UTOOL[2]=PR[60:torch] ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   -12.500  mm,	Y =      .044  mm,	Z =   395.000  mm,
	W =     -.242 deg,	P =    45.000 deg,	R =   180.000 deg
};
/END
