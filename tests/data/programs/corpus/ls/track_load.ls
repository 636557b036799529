/PROG  TRACK_LOAD
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "load along the track";
PROG_SIZE	= 2310;
CREATE		= DATE 24-03-11  TIME 08:12:40;
MODIFIED	= DATE 24-03-12  TIME 14:02:16;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 6;
MEMORY_SIZE	= 2750;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/APPL
/MN
   1:  UFRAME_NUM=2 ;
   2:  UTOOL_NUM=1 ;
   3:J P[1] 100% CNT100    ;
   4:L P[2] 400mm/sec FINE    ;
   5:J P[3] 100% CNT100    ;
   6:L P[4] 400mm/sec FINE    ;
/POS
P[1]{
   GP1:
	UF : 2, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   107.968  mm,	Y =  -578.752  mm,	Z =   122.981  mm,
	W =   150.685 deg,	P =     4.472 deg,	R =   175.338 deg,
	E1=     0.000  mm
};
P[2]{
   GP1:
	UF : 2, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   127.766  mm,	Y =  -539.509  mm,	Z =   -77.576  mm,
	W =   151.219 deg,	P =     2.823 deg,	R =   174.191 deg,
	E1=     0.000  mm
};
P[3]{
   GP1:
	UF : 2, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   111.118  mm,	Y =   229.072  mm,	Z =   322.787  mm,
	W =   153.335 deg,	P =     3.807 deg,	R =   175.857 deg,
	E1=   800.000  mm
};
P[4]{
   GP1:
	UF : 2, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   115.006  mm,	Y =  1006.935  mm,	Z =   464.383  mm,
	W =   153.406 deg,	P =     2.536 deg,	R =   175.317 deg,
	E1=  1600.000  mm
};
/END
