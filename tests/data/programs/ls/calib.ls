/PROG  CALIB
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "calibration poses";
PROG_SIZE	= 2410;
CREATE		= DATE 24-03-04  TIME 07:12:40;
MODIFIED	= DATE 24-03-11  TIME 15:02:18;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 14;
MEMORY_SIZE	= 2880;
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
   1:  !Calibration poses: measured by the tracker ;
   2:  UFRAME_NUM=0 ;
   3:  UTOOL_NUM=3 ;
   4:  R[10:pose]=0    ;
   5:J P[1] 40% FINE    ;
   6:  CALL MEASURE(1) ;
   7:J P[2] 40% FINE    ;
   8:  CALL MEASURE(2) ;
   9:J P[3] 40% FINE    ;
  10:  CALL MEASURE(3) ;
  11:L P[4] 200mm/sec FINE    ;
  12:  CALL MEASURE(4) ;
  13:J P[5] 40% FINE    ;
  14:  CALL MEASURE(5) ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 3,		CONFIG : 'N U T, 0, 1, 0',
	X =  1800.000  mm,	Y =  -300.000  mm,	Z =   900.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg,
	E1=     0.000  mm
};
P[2]{
   GP1:
	UF : 0, UT : 3,		CONFIG : 'N U T, 0, 0, -1',
	X =  2000.000  mm,	Y =   200.000  mm,	Z =  1100.000  mm,
	W =  -170.000 deg,	P =    10.000 deg,	R =   160.000 deg,
	E1=     0.000  mm
};
P[3]{
   GP1:
	UF : 0, UT : 3,		CONFIG : 'F U T, 0, 0, -1',
	X =  2200.000  mm,	Y =  -500.000  mm,	Z =   700.000  mm,
	W =   175.000 deg,	P =    -5.000 deg,	R =  -160.000 deg,
	E1=     0.000  mm
};
P[4]{
   GP1:
	UF : 0, UT : 3,		CONFIG : 'N U T, 0, 1, 0',
	X =  2200.000  mm,	Y =  -500.000  mm,	Z =   500.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =  -160.000 deg,
	E1=     0.000  mm
};
P[5]{
   GP1:
	UF : 0, UT : 3,		CONFIG : 'F U T, 0, 0, 1',
	X =  1700.000  mm,	Y =   400.000  mm,	Z =  1300.000  mm,
	W =   160.000 deg,	P =    20.000 deg,	R =   150.000 deg,
	E1=     0.000  mm
};
/END
